"""A line search that never lets the cloth pass through itself: each iteration proposes a step dx,
asks how far along x -> x + dx every pair of features stays apart (earliest_impact), and moves a
safe fraction of that way. Two procedural sheets that a full step would push through each other.
"""

import clothcd

F, V0, V1 = clothcd.procedural.stacked_sheets(12)
detector = clothcd.SelfDetector(F, V0, thickness=1e-3)
x = V0.copy()
dx = V1 - V0  # the step the solver proposes, every iteration (a full step crosses)
for iteration in range(4):
    toi, kind, ids = detector.earliest_impact(x, x + dx)
    alpha = 1.0 if kind == "none" else 0.8 * toi
    x += alpha * dx
    print(f"iteration {iteration}: toi {toi:.6f} ({kind} {ids}), step {alpha:.6f}")
print(f"moved {float(abs(x - V0).max()):.6f} of {float(abs(dx).max()):.6f}")
