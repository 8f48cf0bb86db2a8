#include "exact_oracle.hpp"

#include <gmpxx.h>

#include <array>
#include <cassert>
#include <utility>
#include <vector>

namespace clothcd::test {

namespace {

// Polynomial in t over Q, coefficients from degree 0 up, no trailing zeros (zero = empty).
using Poly = std::vector<mpq_class>;
using PVec = std::array<Poly, 3>;

void trim(Poly& p) {
  while (!p.empty() && sgn(p.back()) == 0)
    p.pop_back();
}
int deg(const Poly& p) {
  return static_cast<int>(p.size()) - 1;
}

Poly add(const Poly& a, const Poly& b) {
  Poly r(std::max(a.size(), b.size()));
  for (std::size_t i = 0; i < a.size(); ++i)
    r[i] += a[i];
  for (std::size_t i = 0; i < b.size(); ++i)
    r[i] += b[i];
  trim(r);
  return r;
}
Poly neg(Poly a) {
  for (auto& c : a)
    c = -c;
  return a;
}
Poly sub(const Poly& a, const Poly& b) {
  return add(a, neg(b));
}
Poly mul(const Poly& a, const Poly& b) {
  if (a.empty() || b.empty()) return {};
  Poly r(a.size() + b.size() - 1);
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j)
      r[i + j] += a[i] * b[j];
  }
  trim(r);
  return r;
}
mpq_class eval(const Poly& p, const mpq_class& t) {
  mpq_class r = 0;
  for (auto it = p.rbegin(); it != p.rend(); ++it)
    r = r * t + *it;
  return r;
}
int sign_at(const Poly& p, const mpq_class& t) {
  return sgn(eval(p, t));
}
Poly derivative(const Poly& p) {
  Poly r;
  for (std::size_t i = 1; i < p.size(); ++i)
    r.push_back(p[i] * static_cast<long>(i));
  trim(r);
  return r;
}
// a = q b + r with deg r < deg b (b nonzero).
std::pair<Poly, Poly> divmod(Poly a, const Poly& b) {
  assert(!b.empty());
  Poly q(a.size() >= b.size() ? a.size() - b.size() + 1 : 0);
  while (!a.empty() && a.size() >= b.size()) {
    const std::size_t shift = a.size() - b.size();
    const mpq_class c = a.back() / b.back();
    q[shift] = c;
    for (std::size_t i = 0; i < b.size(); ++i)
      a[i + shift] -= c * b[i];
    a.pop_back();  // the leading term cancels exactly
    trim(a);
  }
  trim(q);
  return {q, a};
}
Poly monic(Poly p) {
  if (p.empty()) return p;
  const mpq_class lead = p.back();
  for (auto& c : p)
    c /= lead;
  return p;
}
Poly gcd(Poly a, Poly b) {
  while (!b.empty()) {
    Poly r = divmod(a, b).second;
    a = std::move(b);
    b = std::move(r);
  }
  return monic(a);
}
Poly squarefree(const Poly& p) {
  if (deg(p) < 1) return p;
  return divmod(p, gcd(p, derivative(p))).first;
}

// Sturm count of distinct roots of p in the open interval (lo, hi); p(lo), p(hi) != 0.
int sign_changes(const std::vector<Poly>& seq, const mpq_class& x) {
  int changes = 0, last = 0;
  for (const auto& p : seq) {
    const int s = sign_at(p, x);
    if (s == 0) continue;
    if (last != 0 && s != last) ++changes;
    last = s;
  }
  return changes;
}
std::vector<Poly> sturm(const Poly& p) {
  std::vector<Poly> seq{p, derivative(p)};
  while (!seq.back().empty()) {
    Poly r = divmod(seq[seq.size() - 2], seq.back()).second;
    if (r.empty()) break;
    seq.push_back(neg(r));
  }
  return seq;
}
int count_roots(const std::vector<Poly>& seq, const mpq_class& lo, const mpq_class& hi) {
  return sign_changes(seq, lo) - sign_changes(seq, hi);
}

struct Root {
  bool exact;
  mpq_class value;   // when exact
  mpq_class lo, hi;  // otherwise: the only root of `work` in (lo, hi), work(lo), work(hi) != 0
};

struct Roots {
  Poly work;  // square-free, defines the interval roots; nonzero at their endpoints
  std::vector<Root> roots;
};

// The distinct real roots of p (nonzero) in [0, 1].
Roots isolate(const Poly& p) {
  Roots out;
  Poly work = squarefree(p);
  const mpq_class zero = 0, one = 1;
  auto deflate = [&](const mpq_class& r) {
    out.roots.push_back(Root{true, r, 0, 0});
    work = divmod(work, Poly{-r, 1}).first;
  };
  if (deg(work) >= 1 && sign_at(work, zero) == 0) deflate(zero);
  if (deg(work) >= 1 && sign_at(work, one) == 0) deflate(one);
  while (true) {
    std::vector<Root> found;
    bool restart = false;
    std::vector<std::pair<mpq_class, mpq_class>> stack;
    if (deg(work) >= 1) stack.emplace_back(zero, one);
    const std::vector<Poly> seq = sturm(work);
    while (!stack.empty() && !restart) {
      auto [lo, hi] = stack.back();
      stack.pop_back();
      const int n = count_roots(seq, lo, hi);
      if (n == 0) continue;
      if (n == 1) {
        found.push_back(Root{false, 0, lo, hi});
        continue;
      }
      mpq_class mid = (lo + hi) / 2;
      if (sign_at(work, mid) == 0) {
        deflate(mid);
        restart = true;
        break;
      }
      stack.emplace_back(lo, mid);
      stack.emplace_back(mid, hi);
    }
    if (!restart) {
      out.roots.insert(out.roots.end(), found.begin(), found.end());
      out.work = work;
      return out;
    }
  }
}

// Sign of h at a root.
int sign_at_root(const Roots& rs, const Root& r, const Poly& h) {
  if (r.exact) return sign_at(h, r.value);
  if (h.empty()) return 0;
  const Poly g = gcd(rs.work, h);
  // g divides `work`, whose only root in (lo, hi) is simple: g vanishes there iff it changes sign.
  if (deg(g) >= 1 && sign_at(g, r.lo) * sign_at(g, r.hi) < 0) return 0;
  const std::vector<Poly> hseq = sturm(squarefree(h));
  mpq_class lo = r.lo, hi = r.hi;
  const int slo = sign_at(rs.work, lo);
  while (true) {
    // h(root) != 0: shrinking the interval around the root eventually excludes h's roots.
    if (sign_at(h, lo) != 0 && sign_at(h, hi) != 0 && count_roots(hseq, lo, hi) == 0) {
      return sign_at(h, lo);
    }
    const mpq_class mid = (lo + hi) / 2;
    const int sm = sign_at(rs.work, mid);
    if (sm == 0) return sign_at(h, mid);
    if (sm == slo) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
}

// Exists a root of p in [0, 1] (p nonzero) where every h is > 0.
template <class... H>
bool some_root_where_positive(const Poly& p, const H&... hs) {
  const Roots rs = isolate(p);
  for (const Root& r : rs.roots) {
    if (((sign_at_root(rs, r, hs) > 0) && ...)) return true;
  }
  return false;
}

// Position over the time range [0, t_max], reparametrised to s in [0, 1] (t = s t_max).
PVec motion(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const mpq_class& t_max) {
  PVec r;
  for (int a = 0; a < 3; ++a) {
    const mpq_class c0(x0[a]), c1(x1[a]);
    r[a] = Poly{c0, (c1 - c0) * t_max};
    trim(r[a]);
  }
  return r;
}
PVec sub(const PVec& a, const PVec& b) {
  return {sub(a[0], b[0]), sub(a[1], b[1]), sub(a[2], b[2])};
}
PVec cross(const PVec& a, const PVec& b) {
  return {sub(mul(a[1], b[2]), mul(a[2], b[1])), sub(mul(a[2], b[0]), mul(a[0], b[2])),
          sub(mul(a[0], b[1]), mul(a[1], b[0]))};
}
Poly dot(const PVec& a, const PVec& b) {
  return add(add(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]));
}
bool is_zero(const PVec& v) {
  return v[0].empty() && v[1].empty() && v[2].empty();
}
bool positive_at_zero(const Poly& p) {
  return !p.empty() && sgn(p[0]) > 0;
}

// Points p(t) and a(t) coincide for some t in [0, 1].
bool point_point(const PVec& p, const PVec& a) {
  const PVec d = sub(p, a);
  mpq_class lo = 0, hi = 1;
  for (const Poly& c : d) {
    if (c.empty()) continue;
    if (deg(c) == 0) return false;  // a nonzero constant
    const mpq_class t = -c[0] / c[1];
    lo = std::max(lo, t);
    hi = std::min(hi, t);
  }
  return lo <= hi;
}

// Point p(t) on segment a(t)b(t) for some t in [0, 1].
bool point_edge(const PVec& p, const PVec& a, const PVec& b) {
  if (point_point(p, a) || point_point(p, b)) return true;
  // Otherwise p is strictly between a and b on their (collinear) line: g = 0 and both
  // projections positive.
  const PVec e = sub(b, a), w = sub(p, a);
  const Poly inside_a = dot(w, e), inside_b = dot(sub(p, b), sub(a, b));
  const PVec g = cross(e, w);
  if (is_zero(g)) {
    // Always collinear: the first contact is at an endpoint (above) or at t = 0.
    return positive_at_zero(inside_a) && positive_at_zero(inside_b);
  }
  Poly common;
  for (const Poly& c : g)
    common = gcd(common, c);
  if (deg(common) < 1) return false;
  return some_root_where_positive(common, inside_a, inside_b);
}

}  // namespace

bool exact_vertex_face_contact(const VertexFaceQuery& q, double t_max) {
  const mpq_class tm(t_max);
  const PVec p = motion(q.v_t0, q.v_t1, tm), a = motion(q.f0_t0, q.f0_t1, tm),
             b = motion(q.f1_t0, q.f1_t1, tm), c = motion(q.f2_t0, q.f2_t1, tm);
  if (point_edge(p, a, b) || point_edge(p, b, c) || point_edge(p, c, a)) return true;
  // Strictly inside a non-degenerate coplanar triangle.
  const PVec n = cross(sub(b, a), sub(c, a));
  const Poly s0 = dot(n, cross(sub(b, a), sub(p, a)));
  const Poly s1 = dot(n, cross(sub(c, b), sub(p, b)));
  const Poly s2 = dot(n, cross(sub(a, c), sub(p, c)));
  const Poly f = dot(n, sub(p, a));
  if (f.empty()) {
    // Always coplanar: the first contact is on the boundary (above) or at t = 0.
    return positive_at_zero(s0) && positive_at_zero(s1) && positive_at_zero(s2);
  }
  return some_root_where_positive(f, s0, s1, s2);
}

bool exact_edge_edge_contact(const EdgeEdgeQuery& q, double t_max) {
  const mpq_class tm(t_max);
  const PVec a = motion(q.ea0_t0, q.ea0_t1, tm), b = motion(q.ea1_t0, q.ea1_t1, tm),
             c = motion(q.eb0_t0, q.eb0_t1, tm), d = motion(q.eb1_t0, q.eb1_t1, tm);
  if (point_edge(a, c, d) || point_edge(b, c, d) || point_edge(c, a, b) || point_edge(d, a, b)) {
    return true;
  }
  // A proper crossing: coplanar, not parallel, each segment's endpoints strictly on both sides of
  // the other's line. The products are taken as polynomials, so "opposite sides" is "< 0".
  const PVec ab = sub(b, a), cd = sub(d, c);
  const PVec m = cross(ab, cd);
  const Poly sc = dot(cross(ab, sub(c, a)), m), sd = dot(cross(ab, sub(d, a)), m);
  const Poly sa = dot(cross(cd, sub(a, c)), m), sb = dot(cross(cd, sub(b, c)), m);
  const Poly opp_cd = neg(mul(sc, sd)), opp_ab = neg(mul(sa, sb));
  const Poly f = dot(cross(ab, sub(c, a)), sub(d, a));
  if (f.empty()) return positive_at_zero(opp_cd) && positive_at_zero(opp_ab);
  return some_root_where_positive(f, opp_cd, opp_ab);
}

}  // namespace clothcd::test
