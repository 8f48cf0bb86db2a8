// Collision response: proximity repulsion + friction, CCD passes with inelastic projection,
// rigid impact zones.
#include "clothcd/sim/contact_handler.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "clothcd/bvh/bvh.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "clothcd/ccd/queries.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/sim/intersections.hpp"
#include "fitted_tree.hpp"
#include "seam_links.hpp"
#include "zone_motion.hpp"

namespace clothcd::sim {
namespace {

// A contact as four points with signed weights c_k (docs/simulator.md 3.2): VF is
// (1, -w0, -w1, -w2), EE is (1 - s, s, -(1 - t), -t). `n` points from the negative side to the
// positive one; `gap` is the signed distance n . sum c_k x_k at the substep start.
struct Contact {
  std::array<int, 4> id{};
  std::array<bool, 4> on_body{};
  std::array<double, 4> c{};
  Vec3 n = Vec3::Zero();
  double gap = 0.0;
  double sep = 0.0;  // CCD separation this pair was tested with
};

Positions to_matrix(std::span<const Vec3> x) {
  Positions m(static_cast<Eigen::Index>(x.size()), 3);
  for (std::size_t i = 0; i < x.size(); ++i)
    m.row(static_cast<Eigen::Index>(i)) = x[i].transpose();
  return m;
}

CcdResult kernel(const VertexFaceQuery& q, const CcdOptions& o) {
  return vertex_face_ccd(q, o);
}
CcdResult kernel(const EdgeEdgeQuery& q, const CcdOptions& o) {
  return edge_edge_ccd(q, o);
}

bool normalize(Vec3& n) {
  const double l = n.norm();
  if (!(l > 1e-14)) return false;
  n /= l;
  return true;
}

class UnionFind {
 public:
  explicit UnionFind(int n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int find(int a) {
    while (parent_[a] != a) {
      parent_[a] = parent_[parent_[a]];
      a = parent_[a];
    }
    return a;
  }
  // The smaller id becomes the root, so zones do not depend on the merge order.
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (b < a) std::swap(a, b);
    parent_[b] = a;
  }

 private:
  std::vector<int> parent_;
};

}  // namespace

// How closely hits' times of impact are refined (fraction of the substep, early side): the
// response uses the geometry at toi only for its normal and weights. Measured on dress-rumba frame
// 1: 1e-4 -> 5.5 s, 0.05 -> 3.6 s per frame.
constexpr double kToiTolerance = 0.05;
// Bisections of the distance filter before a CCD kernel runs: on multilayer-kick frame 2 a
// restricted pass ran about 16,000 kernels with the whole-step bound alone and about 500 with
// 6 levels; a level costs at most 2^level distance evaluations, far less than a kernel.
constexpr int kFilterDepth = 6;
// Projection sweeps per CCD pass, and the velocity change (in separations per substep) below
// which a sweep counts as converged.
constexpr int kProjectionSweeps = 100;
constexpr double kProjectionTolerance = 0.01;
// Smallest weight at which a contact's cloth vertex gets its own repulsion (repel_pointwise()).
constexpr double kPointwiseWeight = 0.05;
// Zone rounds that still demand the CCD margin; later ones demand only no contact.
constexpr int kMarginRounds = 5;

struct ContactHandler::Impl {
  const ClothModel& model;
  ContactOptions opt;
  detail::SeamLinks links;
  std::optional<SelfDetector> self;
  // The self detector's box area ratio after the first full CCD pass since its tree was built
  // (0: not yet seen). The detector's tree keeps the splits of the shape it was built on; once
  // its boxes have loosened past that (FittedTree::loosened), a substep rebuilds it on its start
  // (the same pairs, faster: multilayer-kick frame 90, the first pass took 96 ms on the frame-0
  // tree, 58 ms rebuilt).
  double self_fit = 0.0;
  // Body: proximity and CCD through the two-mesh detector (cloth A, body B), its trees rebuilt
  // when their boxes have loosened past their fit right after the last build (body_fit: 0 not
  // yet measured; see FittedTree::loosened).
  std::optional<PairDetector> body;
  const Topology* body_topo = nullptr;
  std::array<double, 2> body_fit{0.0, 0.0};
  std::vector<Contact> proximity;
  std::vector<ContactConstraint> constraints;  // see add_constraint()
  std::vector<ContactCoupling> couplings;      // see add_proximity()
  double constraint_gap = 0.0;
  // This substep's CCD impacts so far and their accumulated impulses (see project()).
  std::vector<Contact> impacts;
  std::vector<double> lambda;
  // Triangle pairs already crossing at the substep start (sorted): CCD cannot undo a crossing, so
  // their feature pairs are left out of the CCD response (Baraff, Witkin, Kass 2003) instead of
  // filling every pass and zone round with hits that no velocity can remove.
  std::optional<IntersectionCounter> crossing;
  std::vector<std::pair<int, int>> crossing_self, crossing_body;
  // Cloth vertices inside the body (behind a body face that one of their faces crosses): each
  // moves out along that face's outward normal, `push` metres still to go (see untangle()).
  struct Escape {
    int vertex = -1;
    int body_face = -1;
    Vec3 n = Vec3::Zero();
    double push = 0.0;
  };
  std::vector<Escape> escapes;
  std::vector<std::uint8_t> escaping;  // per cloth vertex
  bool clean_end = false;              // the last substep provably ended crossing-free ...
  std::vector<Vec3> expected_x0;       // ... at these positions
  long long excluded = 0;
  // 1, or 0 in the late zone rounds: there only actual contact (the conservative kernels at zero
  // separation) still counts, so a zone that keeps every pair apart but cannot restore the margin
  // (cloth held between two body points that move differently) is accepted.
  double sep_scale = 1.0;
  // Per-substep scratch.
  std::span<const Vec3> x0, b0, b1;
  std::vector<Vec3> vb;
  std::span<const double> inv_mass;
  double h = 0.0;
  Positions x0m, b0m, b1m;

  Impl(const ClothModel& m, const ContactOptions& o)
      : model(m), opt(o), links(m.num_vertices(), m.seam_links()) {}

  [[nodiscard]] const Vec3& position(const Contact& c, int k, double tau, std::span<const Vec3> v,
                                     Vec3& tmp) const {
    const int i = c.id[k];
    if (c.on_body[k]) {
      tmp = b0[i] + tau * (b1[i] - b0[i]);
    } else {
      tmp = tau == 0.0 ? x0[i] : Vec3(x0[i] + tau * h * v[i]);
    }
    return tmp;
  }
  [[nodiscard]] Vec3 velocity(const Contact& c, int k, std::span<const Vec3> v) const {
    return c.on_body[k] ? vb[c.id[k]] : v[c.id[k]];
  }
  [[nodiscard]] double weight(const Contact& c, int k) const {
    return c.on_body[k] ? 0.0 : inv_mass[c.id[k]];
  }
  [[nodiscard]] Vec3 relative_velocity(const Contact& c, std::span<const Vec3> v) const {
    Vec3 r = Vec3::Zero();
    for (int k = 0; k < 4; ++k)
      r += c.c[k] * velocity(c, k, v);
    return r;
  }
  // Changes the contact's relative velocity by delta * dir; false when every point is fixed.
  bool impulse(const Contact& c, const Vec3& dir, double delta, std::span<Vec3> v) const {
    double denom = 0.0;
    for (int k = 0; k < 4; ++k)
      denom += c.c[k] * c.c[k] * weight(c, k);
    if (!(denom > 0.0)) return false;
    const double j = delta / denom;
    for (int k = 0; k < 4; ++k) {
      if (!c.on_body[k]) v[c.id[k]] += (c.c[k] * j * weight(c, k)) * dir;
    }
    return true;
  }

  // Repulsion point by point: every cloth vertex of one side (weight >= kPointwiseWeight) keeps
  // the other side's cloth vertices, or its body point, from approaching faster than the
  // contact's target; the weighted sum of these is the contact's own condition, which the
  // caller then tops up for the light-weight vertices left out. Why: the contact's single
  // impulse, spread by weight over inverse mass, gives the vertex nearest the contact point a
  // velocity change larger than the contact's deficit. A collar vertex already stopped by its own
  // body contact was thrown off the shoulder at 0.73 m/s because its face's other two vertices
  // still fell onto a body vertex; the membrane pulled it back, and the collar shook at up to
  // 5 m/s (multilayer-rumba frames 1-3, docs/simulator.md). Returns whether an impulse was applied.
  bool repel_pointwise(const Contact& c, double target, bool friction, std::span<Vec3> v) const {
    // Side 0: c_k > 0; side 1: c_k < 0. A body side acts as one point: its weighted velocity.
    std::array<std::array<int, 4>, 2> pts{};
    std::array<int, 2> count{};
    std::array<Vec3, 2> body_v{Vec3::Zero(), Vec3::Zero()};
    std::array<bool, 2> body{false, false};
    for (int k = 0; k < 4; ++k) {
      if (c.c[k] == 0.0) continue;
      const int side = c.c[k] > 0 ? 0 : 1;
      if (c.on_body[k]) {
        body[side] = true;
        body_v[side] += std::abs(c.c[k]) * vb[c.id[k]];
      } else if (std::abs(c.c[k]) >= kPointwiseWeight && inv_mass[c.id[k]] > 0) {
        pts[side][count[side]++] = c.id[k];
      }
    }
    if (body[0]) count[0] = 1;
    if (body[1]) count[1] = 1;
    bool any = false;
    for (int a = 0; a < count[0]; ++a) {
      for (int b = 0; b < count[1]; ++b) {
        const int i = body[0] ? -1 : pts[0][a];
        const int j = body[1] ? -1 : pts[1][b];
        const double wi = i < 0 ? 0.0 : inv_mass[i];
        const double wj = j < 0 ? 0.0 : inv_mass[j];
        if (!(wi + wj > 0)) continue;
        const Vec3 rel = (i < 0 ? body_v[0] : v[i]) - (j < 0 ? body_v[1] : v[j]);
        const double vn = c.n.dot(rel);
        if (vn >= target) continue;
        const double dn = target - vn;
        Vec3 d = (dn / (wi + wj)) * c.n;  // impulse
        if (friction) {
          const Vec3 vt = rel - vn * c.n;
          const double lt = vt.norm();
          if (lt > 0) d -= (std::min(opt.friction * dn, lt) / (wi + wj) / lt) * vt;
        }
        if (i >= 0) v[i] += wi * d;
        if (j >= 0) v[j] -= wj * d;
        any = true;
      }
    }
    return any;
  }

  // Orients n so that the contact's start gap is >= 0; false for a degenerate normal.
  bool finish(Contact& c, Vec3 n, std::span<const Vec3> v, const Vec3& fallback) const {
    if (!normalize(n)) {
      n = fallback;
      if (!normalize(n)) return false;
    }
    Vec3 tmp, s = Vec3::Zero();
    for (int k = 0; k < 4; ++k)
      s += c.c[k] * position(c, k, 0.0, v, tmp);
    c.gap = n.dot(s);
    if (c.gap < 0) {
      n = -n;
      c.gap = -c.gap;
    }
    c.n = n;
    return true;
  }

  // A vertex-face contact at time tau of the substep (0: proximity at the start).
  bool make_vf(Contact& c, int p, bool p_body, int f, bool f_body, double tau,
               std::span<const Vec3> v) const {
    const Face& t = f_body ? body_topo->faces()[f] : model.topology().faces()[f];
    c.id = {p, t[0], t[1], t[2]};
    c.on_body = {p_body, f_body, f_body, f_body};
    std::array<Vec3, 4> q;
    for (int k = 0; k < 4; ++k)
      q[k] = position(c, k, tau, v, q[k]);
    const PointTriangleProximity pr = point_triangle_proximity(q[0], q[1], q[2], q[3]);
    c.c = {1.0, -pr.weights[0], -pr.weights[1], -pr.weights[2]};
    const Vec3 face_n = (q[2] - q[1]).cross(q[3] - q[1]);
    const Vec3 toward = q[0] - pr.closest;
    // Proximity uses the closest-point direction; CCD (touching) the face normal.
    if (tau == 0.0 && pr.distance > 1e-9) return finish(c, toward, v, face_n);
    return finish(c, face_n, v, toward);
  }

  bool make_ee(Contact& c, int ea, bool a_body, int eb, bool b_body, double tau,
               std::span<const Vec3> v) const {
    const Edge& x = a_body ? body_topo->edges()[ea] : model.topology().edges()[ea];
    const Edge& y = b_body ? body_topo->edges()[eb] : model.topology().edges()[eb];
    c.id = {x[0], x[1], y[0], y[1]};
    c.on_body = {a_body, a_body, b_body, b_body};
    std::array<Vec3, 4> q;
    for (int k = 0; k < 4; ++k)
      q[k] = position(c, k, tau, v, q[k]);
    const EdgeEdgeProximity pr = edge_edge_proximity(q[0], q[1], q[2], q[3]);
    c.c = {1.0 - pr.s, pr.s, -(1.0 - pr.t), -pr.t};
    const Vec3 cross = (q[1] - q[0]).cross(q[3] - q[2]);
    const Vec3 toward = pr.closest_a - pr.closest_b;
    if (tau == 0.0 && pr.distance > 1e-9) return finish(c, toward, v, cross);
    return finish(c, cross, v, toward);
  }

  [[nodiscard]] bool vf_linked(int v, int f) const {
    const std::array<int, 1> a{v};
    return links.any_linked(a, model.topology().faces()[f]);
  }
  [[nodiscard]] bool ee_linked(int a, int b) const {
    return links.any_linked(model.topology().edges()[a], model.topology().edges()[b]);
  }

  // The CCD separation of a pair at distance d0 at t0: the configured one, or half the start
  // distance for pairs already closer than twice it (resting contact). A pair inside its own
  // separation at t0 would otherwise be a hit at toi 0 that no non-approaching velocity removes.
  // Negative: the pair touches at t0 and is left to repulsion.
  [[nodiscard]] double separation(double d0) const {
    if (!(d0 > 0.0)) return -1.0;
    return sep_scale * std::min(opt.ccd_thickness, 0.5 * d0);
  }

  // The response needs the first contact only roughly (impulses use the geometry at toi), so the
  // kernels stop refining it early; the toi stays on the early side.
  [[nodiscard]] static CcdOptions ccd_options(double separation) {
    CcdOptions o;
    o.thickness = separation;
    o.toi_tolerance = kToiTolerance;
    return o;
  }

  [[nodiscard]] static bool has(const std::vector<std::pair<int, int>>& l, int a, int b) {
    return std::binary_search(l.begin(), l.end(), std::pair<int, int>(a, b));
  }
  [[nodiscard]] bool self_crossing(int f, int g) const {
    return has(crossing_self, std::min(f, g), std::max(f, g));
  }
  // A feature pair is tangled when a face around one side crosses a face around the other.
  [[nodiscard]] bool vf_tangled(int v, int f) const {
    if (crossing_self.empty()) return false;
    for (int g : model.topology().vertex_faces(v)) {
      if (self_crossing(g, f)) return true;
    }
    return false;
  }
  [[nodiscard]] bool ee_tangled(int a, int b) const {
    if (crossing_self.empty()) return false;
    const Topology& t = model.topology();
    for (int f : t.edge_faces(a)) {
      for (int g : t.edge_faces(b)) {
        if (self_crossing(f, g)) return true;
      }
    }
    return false;
  }
  // Body pairs: (cloth face, body face).
  [[nodiscard]] bool cloth_vertex_body_face_tangled(int v, int g) const {
    if (crossing_body.empty()) return false;
    for (int f : model.topology().vertex_faces(v)) {
      if (has(crossing_body, f, g)) return true;
    }
    return false;
  }
  [[nodiscard]] bool body_vertex_cloth_face_tangled(int u, int f) const {
    if (crossing_body.empty()) return false;
    for (int g : body_topo->vertex_faces(u)) {
      if (has(crossing_body, f, g)) return true;
    }
    return false;
  }
  [[nodiscard]] bool cloth_edge_body_edge_tangled(int a, int b) const {
    if (crossing_body.empty()) return false;
    for (int f : model.topology().edge_faces(a)) {
      for (int g : body_topo->edge_faces(b)) {
        if (has(crossing_body, f, g)) return true;
      }
    }
    return false;
  }

  void find_crossings(const SubstepContext& ctx) {
    static const std::vector<Face> kNoFaces;
    if (!crossing) {
      const bool body = has_body(ctx);
      crossing.emplace(model.topology(), model.seam_links(), body ? *ctx.body_faces : kNoFaces,
                       body ? static_cast<int>(ctx.body_t0.size()) : 0);
    }
    crossing_self.clear();
    crossing_body.clear();
    // A substep that started crossing-free, excluded nothing and resolved every CCD hit ends
    // crossing-free: skip the count when this substep starts where that one ended.
    if (clean_end && std::equal(x0.begin(), x0.end(), expected_x0.begin(), expected_x0.end())) {
      return;
    }
    if (opt.self) crossing_self = crossing->self_pairs(x0);
    if (has_body(ctx)) crossing_body = crossing->body_pairs(x0, b0);
  }

  [[nodiscard]] bool touches_escaping(const Face& f) const {
    return escaping[f[0]] || escaping[f[1]] || escaping[f[2]];
  }

  // The body's faces are wound counter-clockwise seen from outside (the mannequin's signed
  // volume is positive), so a cloth vertex of a face crossing body face g that lies behind g's
  // plane is inside the body. Each such vertex escapes along the outward normal of the deepest
  // face it is behind, to the repulsion distance in front of it.
  void find_escapes() {
    escapes.clear();
    escaping.assign(x0.size(), 0);
    if (crossing_body.empty() || !(opt.untangle_step > 0)) return;
    const auto& cf = model.topology().faces();
    const auto& bf = body_topo->faces();
    std::vector<int> slot(x0.size(), -1);
    for (const auto& [f, g] : crossing_body) {
      const Face& t = bf[g];
      Vec3 n = (b0[t[1]] - b0[t[0]]).cross(b0[t[2]] - b0[t[0]]);
      if (!normalize(n)) continue;
      for (int i : cf[f]) {
        const double depth = n.dot(x0[i] - b0[t[0]]);
        if (!(depth < 0.0) || inv_mass[i] == 0.0) continue;
        const double push = opt.thickness - depth;
        if (slot[i] < 0) {
          slot[i] = static_cast<int>(escapes.size());
          escapes.push_back({i, g, n, push});
        } else if (push > escapes[slot[i]].push) {
          escapes[slot[i]] = {i, g, n, push};
        }
      }
    }
    for (const Escape& e : escapes)
      escaping[e.vertex] = 1;
  }

  void ensure_body(const SubstepContext& ctx) {
    if (body) return;
    DetectOptions o;
    o.thickness = opt.ccd_thickness;
    o.toi_tolerance = kToiTolerance;
    o.distance_filter_depth = kFilterDepth;
    body.emplace(model.topology().faces(), model.num_vertices(), x0m, *ctx.body_faces,
                 static_cast<int>(ctx.body_t0.size()), b0m, o);
    body_topo = &body->topology_b();
  }

  [[nodiscard]] bool has_body(const SubstepContext& ctx) const {
    return opt.body && ctx.body_faces != nullptr && !ctx.body_t0.empty();
  }

  // An escaping vertex's body pairs would hold it inside (see find_escapes()): pairs with a
  // cloth feature touching one are left out of the body's repulsion and CCD.
  [[nodiscard]] bool escapes_vf(int cloth_vertex) const { return escaping[cloth_vertex] != 0; }
  [[nodiscard]] bool escapes_fv(int cloth_face) const {
    return touches_escaping(model.topology().faces()[cloth_face]);
  }
  [[nodiscard]] bool escapes_ee(int cloth_edge) const {
    const Edge& e = model.topology().edges()[cloth_edge];
    return escaping[e[0]] || escaping[e[1]];
  }

  void prepare(const SubstepContext& ctx) {
    x0 = ctx.x0;
    b0 = ctx.body_t0;
    b1 = ctx.body_t1;
    h = ctx.h;
    inv_mass = ctx.inverse_mass;
    x0m = to_matrix(x0);
    proximity.clear();
    constraints.clear();
    couplings.clear();
    excluded = 0;
    if (has_body(ctx)) {
      b0m = to_matrix(b0);
      b1m = to_matrix(b1);
      ensure_body(ctx);  // the crossing counter and the body queries need it
    }
    find_crossings(ctx);
    find_escapes();
    const std::span<const Vec3> none;
    const double dh = opt.thickness;
    if (opt.self) {
      if (!self) {
        DetectOptions o;
        o.culling = Culling::Sound;  // never the unsound cone rules in the simulator
        o.thickness = opt.ccd_thickness;
        o.toi_tolerance = kToiTolerance;
        o.distance_filter_depth = kFilterDepth;
        // The proximity query below (at dh) then reuses the last CCD pass's candidate pairs.
        o.reuse_distance = opt.thickness;
        // Seam-linked vertices count as one point: the seam's sides touch by design.
        o.linked_vertices = model.seam_links();
        self.emplace(model.topology().faces(), model.num_vertices(), x0m, o);
      } else if (self_fit > 0.0 &&
                 detail::FittedTree::loosened(self->bvh().box_area_ratio(), self_fit)) {
        self->rebuild(x0m);  // its boxes are still the last CCD pass's
        self_fit = 0.0;
      }
      const ProximityResult r = self->proximity(x0m, dh);
      for (const auto& p : r.vf) {
        if (vf_linked(p.vertex, p.face)) continue;
        Contact c;
        if (make_vf(c, p.vertex, false, p.face, false, 0.0, none)) add_proximity(c);
      }
      for (const auto& p : r.ee) {
        if (ee_linked(p.edge_a, p.edge_b)) continue;
        Contact c;
        if (make_ee(c, p.edge_a, false, p.edge_b, false, 0.0, none)) add_proximity(c);
      }
    }
    if (has_body(ctx)) body_proximity(dh);
  }

  // Cloth-body contacts within dh at the substep start, in the detector's sorted order: (cloth
  // vertex, body face) pairs also give constraints, the others couplings.
  void body_proximity(double dh) {
    const std::span<const Vec3> none;
    body->clear_active();
    const PairProximityResult r = body->proximity(x0m, b0m, dh);
    refit_body_trees();
    for (const auto& p : r.vf_a_on_b) {
      Contact c;
      if (!escapes_vf(p.vertex) && make_vf(c, p.vertex, false, p.face, true, 0.0, none)) {
        proximity.push_back(c);
        if (opt.body_constraints) add_constraint(c);
      }
    }
    for (const auto& p : r.vf_b_on_a) {
      Contact c;
      if (!escapes_fv(p.face) && make_vf(c, p.vertex, true, p.face, false, 0.0, none)) {
        add_proximity(c);
      }
    }
    for (const auto& p : r.ee) {
      Contact c;
      if (!escapes_ee(p.edge_a) && make_ee(c, p.edge_a, false, p.edge_b, true, 0.0, none)) {
        add_proximity(c);
      }
    }
  }

  // The body detector's trees keep the splits of the shapes they were built on; once either's
  // static boxes (just refit by the proximity query) have loosened past their fit after the last
  // build, both are rebuilt on the substep start. Only the queries' time depends on it.
  void refit_body_trees() {
    const std::array<double, 2> ratio{body->bvh_a().box_area_ratio(),
                                      body->bvh_b().box_area_ratio()};
    if (body_fit[0] == 0.0) {
      body_fit = ratio;
      return;
    }
    if (detail::FittedTree::loosened(ratio[0], body_fit[0]) ||
        detail::FittedTree::loosened(ratio[1], body_fit[1])) {
      body->rebuild(x0m, b0m);
      body_fit = {0.0, 0.0};
    }
  }

  // The normal velocity repulsion asks of a proximity contact: a share of its overlap per substep.
  [[nodiscard]] double repulsion_target(const Contact& c) const {
    return opt.repulsion_fraction * (opt.thickness - c.gap) / h;
  }

  // A proximity contact that no constraint covers; with `coupled_contacts` also a coupling of the
  // solve: the same target as repulsion, the body points' velocity over the substep as a constant.
  void add_proximity(const Contact& c) {
    proximity.push_back(c);
    if (!opt.coupled_contacts) return;
    ContactCoupling cc;
    cc.n = c.n;
    cc.normal_velocity = repulsion_target(c);
    for (int k = 0; k < 4; ++k) {
      cc.c[k] = c.c[k];
      if (c.on_body[k]) {
        cc.body_velocity += c.c[k] * c.n.dot(b1[c.id[k]] - b0[c.id[k]]) / h;
      } else {
        cc.vertex[k] = c.id[k];
      }
    }
    couplings.push_back(cc);
  }

  // Keeps, per cloth vertex, the constraint of its nearest body face (contacts come sorted by
  // vertex). The body point's normal velocity over the substep plus the repulsion target.
  void add_constraint(const Contact& c) {
    const int v = c.id[0];
    if (!(inv_mass[v] > 0)) return;
    Vec3 vb_point = Vec3::Zero();
    for (int k = 1; k < 4; ++k)
      vb_point -= c.c[k] * (b1[c.id[k]] - b0[c.id[k]]) / h;
    const double target = repulsion_target(c);
    const ContactConstraint cc{v, c.n, c.n.dot(vb_point) + target};
    if (!constraints.empty() && constraints.back().vertex == v) {
      if (c.gap < constraint_gap) {
        constraints.back() = cc;
        constraint_gap = c.gap;
      }
      return;
    }
    constraints.push_back(cc);
    constraint_gap = c.gap;
  }

  // What becomes of one self-CCD hit of the detector.
  struct SelfHit {
    enum Fate : std::uint8_t { Dropped, Excluded, Kept } fate = Dropped;
    Contact contact;
  };

  // Dropped pairs (seam-linked, or an escaping vertex's body pairs) are dropped; tangled pairs
  // and pairs touching at t0 are excluded (left to repulsion); a pair farther apart at t0 (d0())
  // than `reach` (what both sides move plus the separation) cannot touch; a resting pair, closer
  // at t0 than twice the CCD separation, is retested at its own separation (see separation());
  // the rest become contacts at the detector's time of impact.
  template <class Query, class Distance, class Make>
  SelfHit settle(bool dropped, bool tangled, double toi, const Query& query, Distance&& d0,
                 Make&& make, double reach = std::numeric_limits<double>::infinity()) const {
    SelfHit r;
    if (dropped) return r;
    if (tangled) {
      r.fate = SelfHit::Excluded;
      return r;
    }
    const double d = d0();
    if (d > reach) return r;
    const double s = separation(d);
    if (s < 0) {
      r.fate = SelfHit::Excluded;
      return r;
    }
    if (s < opt.ccd_thickness) {
      if (distance_filter_culls(query, s, kFilterDepth)) return r;
      const CcdResult rr = kernel(query, ccd_options(s));
      if (!rr.hit) return r;
      toi = rr.toi;
    }
    if (make(r.contact, toi)) {
      r.contact.sep = s;
      r.fate = SelfHit::Kept;
    }
    return r;
  }

  template <class F>
  static auto map_parallel(std::size_t n, F&& f) {
    std::vector<decltype(f(std::size_t{0}))> out(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i)
                          out[i] = f(i);
                      });
    return out;
  }

  // All CCD hits of the motion x0 -> x0 + h v; when `active` is given, only of the pairs with an
  // active cloth vertex (all other pairs move as when they were last tested without a hit).
  std::vector<Contact> hits(const SubstepContext& ctx, std::span<const Vec3> v,
                            const std::vector<int>* active) {
    std::vector<Contact> out;
    std::vector<Vec3> x1(x0.size());
    for (std::size_t i = 0; i < x0.size(); ++i)
      x1[i] = x0[i] + h * v[i];
    const Positions x1m = to_matrix(x1);
    if (opt.self) {
      if (active != nullptr) {
        self->set_active_vertices(*active);
      } else {
        self->clear_active_faces();
      }
      const DetectResult r = self->detect(x0m, x1m);
      if (active == nullptr && self_fit == 0.0) self_fit = self->bvh().box_area_ratio();
      // Each hit in parallel; the contacts are then gathered in the detector's sorted order.
      const auto& faces = model.topology().faces();
      const auto& edges = model.topology().edges();
      const std::vector<SelfHit> vf = map_parallel(r.vf.size(), [&](std::size_t i) {
        const VertexFaceCollision& p = r.vf[i];
        const Face& t = faces[p.face];
        const int q = p.vertex;
        const VertexFaceQuery query{x0[q], x0[t[0]], x0[t[1]], x0[t[2]],
                                    x1[q], x1[t[0]], x1[t[1]], x1[t[2]]};
        return settle(
            vf_linked(q, p.face), vf_tangled(q, p.face), p.toi, query,
            [&] { return point_triangle_proximity(x0[q], x0[t[0]], x0[t[1]], x0[t[2]]).distance; },
            [&](Contact& c, double toi) { return make_vf(c, q, false, p.face, false, toi, v); });
      });
      const std::vector<SelfHit> ee = map_parallel(r.ee.size(), [&](std::size_t i) {
        const EdgeEdgeCollision& p = r.ee[i];
        const Edge& a = edges[p.edge_a];
        const Edge& b = edges[p.edge_b];
        const EdgeEdgeQuery query{x0[a[0]], x0[a[1]], x0[b[0]], x0[b[1]],
                                  x1[a[0]], x1[a[1]], x1[b[0]], x1[b[1]]};
        return settle(
            ee_linked(p.edge_a, p.edge_b), ee_tangled(p.edge_a, p.edge_b), p.toi, query,
            [&] { return edge_edge_proximity(x0[a[0]], x0[a[1]], x0[b[0]], x0[b[1]]).distance; },
            [&](Contact& c, double toi) {
              return make_ee(c, p.edge_a, false, p.edge_b, false, toi, v);
            });
      });
      gather({&vf, &ee}, out);
    }
    if (has_body(ctx)) body_hits(x1m, x1, v, active, out);
    return out;
  }

  // Cloth-body CCD hits: the detector's hits at the full separation, each settled like a self
  // hit. Its distance at t0 is measured within the reach of the pair's motion (a pair farther
  // apart cannot touch), the measure the separation of a resting pair is taken from.
  void body_hits(const Positions& x1m, std::span<const Vec3> x1, std::span<const Vec3> v,
                 const std::vector<int>* active, std::vector<Contact>& out) {
    if (active != nullptr) {
      body->set_active_vertices(*active);
    } else {
      body->clear_active();
    }
    const PairDetectResult r = body->detect(x0m, x1m, b0m, b1m);
    const auto& cf = model.topology().faces();
    const auto& bf = body_topo->faces();
    const auto& ce = model.topology().edges();
    const auto& be = body_topo->edges();
    const double sep = opt.ccd_thickness;
    auto move_c = [&](int i) { return (x1[i] - x0[i]).norm(); };
    auto move_b = [&](int i) { return (b1[i] - b0[i]).norm(); };
    const std::vector<SelfHit> cb = map_parallel(r.vf_a_on_b.size(), [&](std::size_t k) {
      const VertexFaceCollision& p = r.vf_a_on_b[k];
      const int i = p.vertex;
      const Face& t = bf[p.face];
      const double reach = move_c(i) + std::max({move_b(t[0]), move_b(t[1]), move_b(t[2])}) + sep;
      return settle(
          escapes_vf(i), cloth_vertex_body_face_tangled(i, p.face), p.toi,
          VertexFaceQuery{x0[i], b0[t[0]], b0[t[1]], b0[t[2]], x1[i], b1[t[0]], b1[t[1]], b1[t[2]]},
          [&] {
            return point_triangle_distance_if_within(x0[i], b0[t[0]], b0[t[1]], b0[t[2]], reach);
          },
          [&](Contact& c, double toi) { return make_vf(c, i, false, p.face, true, toi, v); },
          reach);
    });
    const std::vector<SelfHit> bc = map_parallel(r.vf_b_on_a.size(), [&](std::size_t k) {
      const VertexFaceCollision& p = r.vf_b_on_a[k];
      const int u = p.vertex;
      const Face& t = cf[p.face];
      const double reach = move_b(u) + std::max({move_c(t[0]), move_c(t[1]), move_c(t[2])}) + sep;
      return settle(
          escapes_fv(p.face), body_vertex_cloth_face_tangled(u, p.face), p.toi,
          VertexFaceQuery{b0[u], x0[t[0]], x0[t[1]], x0[t[2]], b1[u], x1[t[0]], x1[t[1]], x1[t[2]]},
          [&] {
            return point_triangle_distance_if_within(b0[u], x0[t[0]], x0[t[1]], x0[t[2]], reach);
          },
          [&](Contact& c, double toi) { return make_vf(c, u, true, p.face, false, toi, v); },
          reach);
    });
    const std::vector<SelfHit> ee = map_parallel(r.ee.size(), [&](std::size_t k) {
      const EdgeEdgeCollision& p = r.ee[k];
      const Edge& x = ce[p.edge_a];
      const Edge& y = be[p.edge_b];
      const double reach =
          std::max(move_c(x[0]), move_c(x[1])) + std::max(move_b(y[0]), move_b(y[1])) + sep;
      return settle(
          escapes_ee(p.edge_a), cloth_edge_body_edge_tangled(p.edge_a, p.edge_b), p.toi,
          EdgeEdgeQuery{x0[x[0]], x0[x[1]], b0[y[0]], b0[y[1]], x1[x[0]], x1[x[1]], b1[y[0]],
                        b1[y[1]]},
          [&] {
            return edge_edge_distance_if_within(x0[x[0]], x0[x[1]], b0[y[0]], b0[y[1]], reach);
          },
          [&](Contact& c, double toi) {
            return make_ee(c, p.edge_a, false, p.edge_b, true, toi, v);
          },
          reach);
    });
    gather({&cb, &bc, &ee}, out);
  }

  // The kept contacts of settled hits in order; excluded ones are counted.
  void gather(std::initializer_list<const std::vector<SelfHit>*> lists, std::vector<Contact>& out) {
    for (const auto* l : lists) {
      for (const SelfHit& hit : *l) {
        if (hit.fate == SelfHit::Excluded) ++excluded;
        if (hit.fate == SelfHit::Kept) out.push_back(hit.contact);
      }
    }
  }

  // Escaping vertices (find_escapes()) move out of the body, relative to the face they are
  // behind, at up to `untangle_step` per substep. Their body pairs are left out of repulsion and
  // CCD this substep; self CCD still guards their motion against the rest of the cloth.
  void untangle(std::span<Vec3> v) const {
    for (const Escape& e : escapes) {
      const Face& t = body_topo->faces()[e.body_face];
      const Vec3 vg = (vb[t[0]] + vb[t[1]] + vb[t[2]]) / 3.0;
      const double target = std::min(e.push, opt.untangle_step) / h;
      const double vn = e.n.dot(v[e.vertex] - vg);
      if (vn < target) v[e.vertex] += (target - vn) * e.n;
    }
  }

  // The ids whose flag is set.
  static std::vector<int> flagged(const std::vector<std::uint8_t>& flag) {
    std::vector<int> ids;
    for (int i = 0; i < static_cast<int>(flag.size()); ++i) {
      if (flag[i]) ids.push_back(i);
    }
    return ids;
  }

  CollisionStats respond(const SubstepContext& ctx, std::span<Vec3> v) {
    CollisionStats st;
    const int n = model.num_vertices();
    vb.assign(b0.size(), Vec3::Zero());
    if (has_body(ctx)) {
      for (std::size_t i = 0; i < b0.size(); ++i)
        vb[i] = (b1[i] - b0[i]) / h;
    }
    // 1. Repulsion and friction (sorted pairs, Gauss-Seidel), sweeping until no pair approaches
    // faster than its target (one sweep left coupled pairs approaching, and each became a CCD
    // hit, a constraint and a vertex of every later pass's scope); friction in the first sweep.
    st.proximity_pairs = static_cast<long long>(proximity.size());
    for (int sweep = 0; sweep < opt.repulsion_sweeps; ++sweep) {
      bool any = false;
      for (const Contact& c : proximity) {
        const double target = repulsion_target(c);
        const bool friction = sweep == 0 && opt.friction > 0;
        if (opt.pointwise_repulsion && repel_pointwise(c, target, friction, v)) any = true;
        const Vec3 rel = relative_velocity(c, v);
        const double vn = c.n.dot(rel);
        if (vn >= target) continue;
        const double dn = target - vn;
        if (!impulse(c, c.n, dn, v)) continue;
        any = true;
        if (!friction) continue;
        const Vec3 vt = rel - vn * c.n;
        const double lt = vt.norm();
        if (lt > 0) impulse(c, -vt / lt, std::min(opt.friction * dn, lt), v);
      }
      if (!any) break;
    }
    untangle(v);
    // 2. CCD passes with inelastic impulses; later passes test only faces whose vertices moved.
    std::vector<std::uint8_t> touched(n, 0);
    std::vector<int> active;
    impacts.clear();
    lambda.clear();
    bool clean = false;
    for (int pass = 0; pass < opt.ccd_iterations; ++pass) {
      const std::vector<Contact> hs =
          hits(ctx, v, pass == 0 || opt.full_passes ? nullptr : &active);
      ++st.ccd_passes;
      st.ccd_hits += static_cast<long long>(hs.size());
      if (hs.empty()) {
        clean = true;
        break;
      }
      std::fill(touched.begin(), touched.end(), 0);
      project(hs, v, touched);
      active = flagged(touched);
    }
    if (!clean) zones(ctx, v, touched, st);
    sep_scale = 1.0;
    if (opt.self) self->clear_active_faces();
    st.excluded = excluded;
    clean_end =
        st.unresolved == 0 && excluded == 0 && crossing_self.empty() && crossing_body.empty();
    if (clean_end) {
      expected_x0.resize(x0.size());
      for (std::size_t i = 0; i < x0.size(); ++i)
        expected_x0[i] = x0[i] + h * v[i];
    }
    return st;
  }

  // Adds this pass's hits to the substep's impacts and projects v onto all of them at once:
  // projected Gauss-Seidel on the linearized constraints n . (sum c_k v_k) >= (2 sep - gap) / h
  // with accumulated impulses >= 0, i.e. close to the mass-weighted nearest velocities that
  // satisfy every impact found so far (inelastic projection, Harmon et al. 2008). A pair hit
  // again keeps its earlier constraints beside the new one, so the linearization's errors are
  // fixed by accumulation instead of by the pair flipping between normals. Resolving each
  // pass's hits alone, as before, undid earlier passes' work: on multilayer-kick frames 1-3 the
  // rigid zones then ran in every substep and the frames ended with 120 / 243 / 363 crossing
  // pairs, against 0 zones and 0 crossings with this.
  void project(const std::vector<Contact>& hs, std::span<Vec3> v,
               std::vector<std::uint8_t>& touched) {
    for (const Contact& c : hs) {
      impacts.push_back(c);
      lambda.push_back(0.0);
    }
    // The next pass must retest this pass's hits and every pair with a vertex whose velocity the
    // projection changes; every other pair keeps a motion already tested without a hit.
    std::vector<std::pair<int, Vec3>> before;
    for (const Contact& c : impacts) {
      for (int k = 0; k < 4; ++k) {
        if (!c.on_body[k]) before.emplace_back(c.id[k], v[c.id[k]]);
      }
    }
    std::vector<double> denom(impacts.size(), 0.0);
    for (std::size_t i = 0; i < impacts.size(); ++i) {
      for (int k = 0; k < 4; ++k)
        denom[i] += impacts[i].c[k] * impacts[i].c[k] * weight(impacts[i], k);
    }
    for (int sweep = 0; sweep < kProjectionSweeps; ++sweep) {
      double worst = 0.0;
      for (std::size_t i = 0; i < impacts.size(); ++i) {
        const Contact& c = impacts[i];
        if (!(denom[i] > 0.0)) continue;
        // End the substep at least twice the pair's separation apart, or (a pair already that
        // close) no closer than it started.
        const double target = (2.0 * c.sep - c.gap) / h;
        const double vn = c.n.dot(relative_velocity(c, v));
        const double next = std::max(0.0, lambda[i] + (target - vn) / denom[i]);
        const double dl = next - lambda[i];
        if (dl == 0.0) continue;
        lambda[i] = next;
        worst = std::max(worst, std::abs(dl) * denom[i]);
        for (int k = 0; k < 4; ++k) {
          if (!c.on_body[k]) v[c.id[k]] += (c.c[k] * dl * weight(c, k)) * c.n;
        }
      }
      if (worst <= kProjectionTolerance * opt.ccd_thickness / h) break;
    }
    for (const auto& [i, vi] : before) {
      if (v[i] != vi) touched[i] = 1;
    }
    for (const Contact& c : hs) {
      for (int k = 0; k < 4; ++k) {
        if (!c.on_body[k]) touched[c.id[k]] = 1;
      }
    }
  }

  // Impact zones (Provot 1997), each moved by one invertible linear map; a zone touching the
  // body or a pinned vertex follows those anchors (body points have infinite mass).
  void zones(const SubstepContext& ctx, std::span<Vec3> v, std::vector<std::uint8_t>& changed,
             CollisionStats& st) {
    const int n = model.num_vertices();
    UnionFind uf(n);
    std::vector<std::uint8_t> in_zone(n, 0);
    // A cloth vertex, the body point it touches (at t0) and the velocity it must follow there.
    struct Anchor {
      int vertex = -1;
      Vec3 point, velocity;
    };
    std::vector<Anchor> anchors;
    // Per substep: 0.1 mm with the scenes' settings (dress-rumba frames 1-12: no body crossing
    // and max stretch 0.96, against 25 crossing pairs and 1.2-3.2 without it).
    const double anchor_push = std::max(2.0 * opt.ccd_thickness, 0.1 * opt.thickness);
    std::vector<int> vertex_anchor_count(n, 0);
    std::vector<int> active = flagged(changed);
    const auto& mass = model.mass();
    // The zones run until no hit is left or for `zone_rounds`. (With zones that bent, an exit
    // after 3 rounds without fewer hits saved time; with rigid zones it cost crossings: twist
    // frames 38-43 had 0 / 0 / 0 / 0 / 5 / 5 crossing pairs without it, 171 by frame 41 with it.)
    for (int round = 0;; ++round) {
      sep_scale = round >= std::min(kMarginRounds, opt.zone_rounds / 2) ? 0.0 : 1.0;
      const std::vector<Contact> hs = hits(ctx, v, opt.full_passes ? nullptr : &active);
      if (hs.empty()) break;
      if (round == opt.zone_rounds) {
        st.unresolved = static_cast<long long>(hs.size());
        break;
      }
      ++st.zone_rounds;
      for (const Contact& c : hs) {
        int first = -1;
        Vec3 body_p = Vec3::Zero(), body_v = Vec3::Zero();
        double body_w = 0.0;
        for (int k = 0; k < 4; ++k) {
          if (c.on_body[k]) {
            body_p += std::abs(c.c[k]) * b0[c.id[k]];
            body_v += std::abs(c.c[k]) * vb[c.id[k]];
            body_w += std::abs(c.c[k]);
            continue;
          }
          in_zone[c.id[k]] = 1;
          if (first < 0) {
            first = c.id[k];
          } else {
            uf.unite(first, c.id[k]);
          }
        }
        if (body_w > 0) {
          for (int k = 0; k < 4; ++k) {
            // Follow the body point, plus a small push out along the contact normal (the cloth
            // side is where its weights point): matching the body's velocity alone keeps a
            // near-zero gap that the body's own deformation then closes.
            if (!c.on_body[k]) {
              const double side = c.c[k] > 0 ? 1.0 : -1.0;
              anchors.push_back(
                  {c.id[k], body_p / body_w, body_v / body_w + side * anchor_push / h * c.n});
            }
          }
        }
      }
      // Members of each zone, in vertex order.
      std::vector<std::vector<int>> members;
      std::vector<int> zone_of(n, -1), root_zone(n, -1);
      for (int i = 0; i < n; ++i) {
        if (!in_zone[i]) continue;
        const int r = uf.find(i);
        if (root_zone[r] < 0) {
          root_zone[r] = static_cast<int>(members.size());
          members.emplace_back();
        }
        zone_of[i] = root_zone[r];
        members[zone_of[i]].push_back(i);
      }
      std::fill(vertex_anchor_count.begin(), vertex_anchor_count.end(), 0);
      std::vector<std::vector<int>> zone_anchors(members.size());
      for (std::size_t a = 0; a < anchors.size(); ++a) {
        const int i = anchors[a].vertex;
        zone_anchors[zone_of[i]].push_back(static_cast<int>(a));
        ++vertex_anchor_count[i];
      }
      std::fill(changed.begin(), changed.end(), 0);
      st.zones = static_cast<int>(members.size());
      for (std::size_t z = 0; z < members.size(); ++z) {
        const auto& m = members[z];
        st.largest_zone = std::max(st.largest_zone, static_cast<int>(m.size()));
        bool anchored = !zone_anchors[z].empty();  // touches the body or a pin
        for (int i : m) {
          changed[i] = 1;
          anchored = anchored || inv_mass[i] == 0.0;
        }
        // The zone moves by an invertible linear map of its start positions over the substep, so
        // nothing inside it can collide: free zones move rigidly and keep their momentum and
        // angular momentum (Provot 1997); zones touching the body or a pin take the affine motion
        // closest to the body's velocities at the points they touch (and the pins') where those
        // fix one, else the rigid one. Affine, multilayer-kick held frames 67-70 where rigid
        // zones gave up (a body that bends is not rigid under a zone). Fitted at the cloth
        // vertices instead, each given its contacts' body velocity, the fit was off wherever a
        // body point touched a long cloth edge or face: on multilayer-kick frame 69 (stretch 12)
        // one contact anchored vertices 12 cm apart to one velocity on a turning leg, the fit
        // missed the anchors by 1.65 mm per substep, and the zones gave up (312 body pairs; 104
        // with this). Letting each vertex follow its own anchor instead bent the zone, and on the
        // multilayer the zone rounds then stalled on self hits inside it.
        std::vector<Vec3> points, velocities;
        std::vector<double> weights;
        for (int i : m) {
          if (!anchored) {
            points.push_back(x0[i]);
            velocities.push_back(v[i]);
            weights.push_back(mass[i]);
          } else if (inv_mass[i] == 0.0) {
            points.push_back(x0[i]);
            velocities.push_back(v[i]);
            weights.push_back(1.0);
          }
        }
        for (int a : zone_anchors[z]) {
          const Anchor& an = anchors[static_cast<std::size_t>(a)];
          points.push_back(an.point);
          velocities.push_back(an.velocity);
          weights.push_back(1.0 / vertex_anchor_count[an.vertex]);
        }
        std::optional<detail::AffineMotion> am;
        if (anchored && opt.affine_zones) am = detail::fit_affine(points, velocities, weights, h);
        const detail::RigidMotion rm =
            am ? detail::RigidMotion{} : detail::fit_rigid(points, velocities, weights);
        for (int i : m) {
          if (inv_mass[i] != 0.0) v[i] = am ? am->at(x0[i]) : rm.at(x0[i]);
        }
      }
      active = flagged(changed);
    }
  }
};

ContactHandler::ContactHandler(const ClothModel& model, const ContactOptions& options)
    : options_(options), impl_(std::make_unique<Impl>(model, options)) {}
ContactHandler::~ContactHandler() = default;

void ContactHandler::prepare(const SubstepContext& ctx) {
  impl_->prepare(ctx);
}

void ContactHandler::contact_couplings(std::vector<ContactCoupling>& out) const {
  out = impl_->couplings;
}

void ContactHandler::contact_constraints(std::vector<ContactConstraint>& out) const {
  out = impl_->constraints;
}

CollisionStats ContactHandler::respond(const SubstepContext& ctx, std::span<Vec3> v_star) {
  return impl_->respond(ctx, v_star);
}

}  // namespace clothcd::sim
