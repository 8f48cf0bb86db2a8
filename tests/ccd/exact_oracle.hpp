#pragma once
// Exact reference for zero-thickness CCD, in rational arithmetic (GMP). Doubles convert to
// rationals exactly, so the answer is the exact one for the given double coordinates.
//
// Decomposition (argued in exact_oracle.cpp): a VF contact is a vertex-edge contact on one of the
// triangle's edges or a time where the vertex is strictly inside the (coplanar, non-degenerate)
// triangle; an EE contact is an endpoint-edge contact or a proper crossing. Interior events are
// checked at the real roots of the coplanarity polynomial (isolated with Sturm sequences, signs
// at algebraic roots decided exactly), or at t = 0 when that polynomial vanishes identically.

#include "clothcd/ccd/queries.hpp"

namespace clothcd::test {

/// Whether the features touch at some t in [0, t_max] (t_max in [0, 1]).
[[nodiscard]] bool exact_vertex_face_contact(const VertexFaceQuery& q, double t_max = 1.0);
[[nodiscard]] bool exact_edge_edge_contact(const EdgeEdgeQuery& q, double t_max = 1.0);

}  // namespace clothcd::test
