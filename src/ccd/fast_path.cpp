#include "ccd/fast_path.hpp"

#include <algorithm>
#include <cmath>

#include "ccd/certify.hpp"
#include "ccd/refine.hpp"

namespace clothcd::ccd_detail {

namespace {

// Ranges still undecided at this depth (2^-10 of the step) go to the inclusion solver.
constexpr int kMaxLevel = kFastPathMaxLevel;
// Ranges examined (with the inside test) per query; past it the inclusion solver takes the rest of
// the step. Bounds the cost of flat cubics (near-coplanar motion) whose sign is never certain.
constexpr int kBudget = kFastPathBudget;
// The inside test (several times the cost of a halving) starts at kFirstInsideLevel: the cubic's
// own halving first discards the quarters of the step without a root, which spares most inside
// tests; deeper starts cost more on near-coplanar (flat) cubics.
// Subdivision error bounds hold to this depth.
constexpr int kMaxRefine = 40;

struct Node {
  double b[4];
  double lo, hi;
  int level;
};

}  // namespace

double first_root_bound(const double (&b)[4], double lo, double hi, int level, double e,
                        int target) {
  Node stack[kMaxRefine + 2];
  int n = 0;
  stack[n++] = Node{{b[0], b[1], b[2], b[3]}, lo, hi, level};
  while (n > 0) {
    const Node nd = stack[--n];
    if (one_sign(nd.b, e)) continue;
    if (nd.level >= target) return nd.lo;
    const double mid = (nd.lo + nd.hi) * 0.5;
    Node l{{}, nd.lo, mid, nd.level + 1}, r{{}, mid, nd.hi, nd.level + 1};
    halve(nd.b, l.b, r.b);
    stack[n++] = r;
    stack[n++] = l;
  }
  // Unreachable when the bounds hold (the range has a certain sign change); stay conservative.
  return lo;
}

int toi_target_level(double toi_tolerance) {
  if (!(toi_tolerance > 0)) return kMaxRefine;
  int exp = 0;
  std::frexp(toi_tolerance, &exp);  // 2^(exp-1) <= tol < 2^exp
  return std::clamp(1 - exp, 0, kMaxRefine);
}

namespace {

// The search of fast_path_solve down to depth `max_level`. `undecided(lo, hi)` receives what the
// search cannot decide itself: a range still undecided at max_level, or, past the budget, the rest
// of the step [lo, 1] (then the search ends whatever it returns); it returns true to end the
// search. Sets `out` for a certified hit.
template <class Undecided>
void search(Kind kind, const Motion& m, const BernsteinCubic& c, int target, int max_level,
            FastOutcome& out, Undecided&& undecided) {
  const double e = subdivision_error(c);
  const InsideData data = inside_data(kind, m);
  Node stack[kMaxLevel + 2];
  int n = 0;
  stack[n++] = Node{{c.k[0], c.k[1], c.k[2], c.k[3]}, 0.0, 1.0, 0};
  int visited = 0;
  auto split = [&](const Node& nd) {
    const double mid = (nd.lo + nd.hi) * 0.5;
    Node l{{}, nd.lo, mid, nd.level + 1}, r{{}, mid, nd.hi, nd.level + 1};
    halve(nd.b, l.b, r.b);
    stack[n++] = r;
    stack[n++] = l;
  };
  // Depth-first, earlier half on top: when a range is examined, every earlier time is settled
  // (no contact there), so the first contact found is the first contact of the step.
  while (n > 0) {
    const Node nd = stack[--n];
    if (one_sign(nd.b, e)) continue;
    if (++visited > kBudget) {
      undecided(nd.lo, 1.0);
      return;
    }
    if (nd.level < kFirstInsideLevel) {
      split(nd);
      continue;
    }
    double u = 0, v = 0;
    const Inside in = inside_over(data, nd.lo, nd.hi, u, v);
    if (in == Inside::No) continue;
    if (in == Inside::Yes && sign_change(nd.b, e)) {
      // A root with the contact point strictly inside: a contact in this range, and none before.
      out.hit = true;
      out.certified = true;
      out.toi = first_root_bound(nd.b, nd.lo, nd.hi, nd.level, e, std::max(target, nd.level));
      out.u = u;
      out.v = v;
      return;
    }
    if (nd.level >= max_level) {
      if (undecided(nd.lo, nd.hi)) return;
      continue;
    }
    split(nd);
  }
}

}  // namespace

FastOutcome fast_path_solve(Kind kind, const Motion& m, const BernsteinCubic& c,
                            const InclusionParams& p) {
  FastOutcome out;
  InclusionParams q = p;
  search(kind, m, c, toi_target_level(p.toi_tolerance), kMaxLevel, out, [&](double lo, double hi) {
    q.t_lo = lo;
    q.t_hi = hi;
    const InclusionOutcome o = bounded_inclusion_solve(kind, m, q);
    out.boxes += o.boxes;
    if (o.hit) {
      out.hit = true;
      out.toi = o.toi;
      out.u = o.u;
      out.v = o.v;
    }
    return o.hit;
  });
  return out;
}

bool fast_path_search(Kind kind, const Motion& m, const BernsteinCubic& c, int target,
                      int max_level, FastOutcome& out) {
  bool decided = true;
  search(kind, m, c, target, max_level, out, [&](double, double) {
    decided = false;
    return true;
  });
  return decided;
}

}  // namespace clothcd::ccd_detail
