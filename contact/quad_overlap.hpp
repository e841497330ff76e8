#pragma once
// Overlap of convex quadrilaterals, kQuadLanes pairs at a time: the force terms of the joint law
// of rigid_contact.hpp (|O|, its centroid G, the normal n and the chord) for every block pair of
// four-sided pieces, which is nearly every pair of a masonry structure.
//
// Each edge is clipped by the other quadrilateral's four side lines as a parametric segment
// (Cyrus and Beck, "Generalized two- and three-dimensional clipping", Computers & Graphics 3
// (1978)): P's edge from p_k to p_k+1 keeps the parameters t in [t0, t1], t0 the largest
// parameter where it enters a side line of Q, t1 the smallest where it leaves one. The kept
// pieces of P's edges (inside Q) and of Q's edges (inside P) are the boundary of O, each
// counter-clockwise, so Green's sums of rigid_contact.hpp run over them in any order, and
// N_P is the sum of the kept pieces of P's edges turned outward. Every lane does the same
// arithmetic with selects in place of branches, so the lanes fill one vector register
// (GCC's vector extensions).
// (Rejected for these pairs: Sutherland and Hodgman's clipping, which rigid_contact.cpp keeps
// for other pieces and for the joints' energy. Its vertex count depends on the data, so it
// runs one pair at a time: on church B the overlaps took 216 000 instructions a step that way
// (a portable AVX2 build), 142 000 in batches; its step took 25.7 us one pair at a time,
// 20.1 us in batches.)
//
// Ties. A vertex of P on a side line of Q counts as inside it, a vertex of Q on a side line of P
// as outside: where the two outlines share a stretch of line, it is counted once, as P's.
//
// The two crossing points (for the chord's middle) are the ends of the kept pieces of P's edges
// that do not continue into the kept piece of the next (or previous) edge at a vertex of P.
// Green's sums are taken about the first kept point, a point of O, so that a sliver's terms
// are of its own size.

namespace voussoir {

// Pairs per batch: the doubles of one vector register (AVX-512: 8, AVX2 and below: 4; wider
// vectors than the target's are taken apart lane by lane by the compiler). A lane's arithmetic
// does not depend on the width.
#if defined(__AVX512F__)
inline constexpr int kQuadLanes = 8;
#else
inline constexpr int kQuadLanes = 4;
#endif

// The pairs of a batch: the vertices of P and Q (counter-clockwise) relative to an origin near
// them (o), [m], p_x[k][l] the x of P's vertex k in lane l. Unused lanes hold zeros.
struct QuadPairs {
  alignas(64) double px[4][kQuadLanes], py[4][kQuadLanes];
  alignas(64) double qx[4][kQuadLanes], qy[4][kQuadLanes];
  alignas(64) double ox[kQuadLanes], oy[kQuadLanes];
};

// The overlap of each lane's pair, positions absolute (the origin added); `on` nonzero when P
// and Q overlap with an area and their outlines cross (ConvexOverlap's conditions), else the
// other values mean nothing.
struct QuadOverlaps {
  alignas(64) double area[kQuadLanes];                // |O| [m2]
  alignas(64) double gx[kQuadLanes], gy[kQuadLanes];  // G [m]
  alignas(64) double nx[kQuadLanes], ny[kQuadLanes];  // n, unit, out of P into Q
  alignas(64) double chord[kQuadLanes];               // |N_P| [m]
  alignas(64) double mx[kQuadLanes], my[kQuadLanes];  // the middle of the crossing points [m]
  alignas(64) long on[kQuadLanes];
};

// The bodies of a batch's pairs at their current poses, per lane: P's body and Q's, each by its
// centroid's displacement (ux, uy) and cos(theta) - 1, sin(theta) of its rotation (zeros for a
// body without a pose of its own, and for unused lanes).
struct QuadPoses {
  alignas(64) double p_ux[kQuadLanes], p_uy[kQuadLanes], p_cm1[kQuadLanes], p_s[kQuadLanes];
  alignas(64) double q_ux[kQuadLanes], q_uy[kQuadLanes], q_cm1[kQuadLanes], q_s[kQuadLanes];
};

// A batch at the bodies' poses: `ref` holds the vertices' reference positions relative to P's
// first vertex (and that vertex in ox, oy), `offset` each vertex's offset r from its body's
// reference centroid. Each vertex is displaced by u = (ux, uy) + (R - I) r, and the batch is
// placed relative to P's first displaced vertex: the numbers of RigidContact's one-pair path,
// which displaces every vertex and subtracts.
void quad_place(const QuadPairs& ref, const QuadPairs& offset, const QuadPoses& pose,
                QuadPairs& out);

// The overlaps of the batch's pairs, lane by lane.
void quad_overlaps(const QuadPairs& in, QuadOverlaps& out);

}  // namespace voussoir
