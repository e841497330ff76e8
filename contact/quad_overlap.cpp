// Overlap of convex quadrilaterals, a batch of pairs per call (the method in quad_overlap.hpp).

#include "contact/quad_overlap.hpp"

#include <cstdint>
#include <cstring>

namespace voussoir {

namespace {

// One value per lane, and a lane mask (all bits set where true): GCC's vector extensions.
using Lanes = double __attribute__((vector_size(kQuadLanes * sizeof(double))));
using Mask = std::int64_t __attribute__((vector_size(kQuadLanes * sizeof(std::int64_t))));

inline Lanes load(const double* x) {
  Lanes v;
  std::memcpy(&v, x, sizeof v);
  return v;
}
inline void store(double* x, Lanes v) {
  std::memcpy(x, &v, sizeof v);
}
inline Lanes splat(double x) {
  return Lanes{} + x;
}
inline Lanes select(Mask m, Lanes a, Lanes b) {
  return m ? a : b;
}

// The kept piece [t0, t1] of the edge from (ax, ay) to (bx, by) against the four side lines
// whose signed distances (times the line's length, >= 0 inside) at the edge's ends are da[j],
// db[j]; `strict`: a distance of 0 counts as outside. kept: the lanes where the piece has a
// length.
struct Piece {
  Lanes t0, t1, sx, sy, ex, ey;
  Mask kept;
};

[[gnu::always_inline]] inline Piece clip_edge(Lanes ax, Lanes ay, Lanes bx, Lanes by,
                                              const Lanes (&da)[4], const Lanes (&db)[4],
                                              bool strict) {
  const Lanes zero = splat(0.0), one = splat(1.0);
  Lanes t0 = zero, t1 = one;
  Mask empty{};  // all lanes false
  for (int j = 0; j < 4; ++j) {
    const Mask in_a = strict ? da[j] > zero : da[j] >= zero;
    const Mask in_b = strict ? db[j] > zero : db[j] >= zero;
    const Mask enters = ~in_a & in_b, leaves = in_a & ~in_b;
    const Lanes t = da[j] / select(enters | leaves, da[j] - db[j], one);
    t0 = select(enters & (t > t0), t, t0);
    t1 = select(leaves & (t < t1), t, t1);
    empty |= ~in_a & ~in_b;
  }
  Piece p;
  p.t0 = t0, p.t1 = t1;
  p.kept = ~empty & (t0 < t1);
  const Lanes dx = bx - ax, dy = by - ay;
  p.sx = ax + t0 * dx, p.sy = ay + t0 * dy;
  // The edge's own end where it is kept to the end, not its round-off.
  p.ex = select(t1 == one, bx, ax + t1 * dx);
  p.ey = select(t1 == one, by, ay + t1 * dy);
  return p;
}

}  // namespace

void quad_place(const QuadPairs& ref, const QuadPairs& offset, const QuadPoses& pose,
                QuadPairs& out) {
  const Lanes p_ux = load(pose.p_ux), p_uy = load(pose.p_uy);
  const Lanes p_cm1 = load(pose.p_cm1), p_s = load(pose.p_s);
  const Lanes q_ux = load(pose.q_ux), q_uy = load(pose.q_uy);
  const Lanes q_cm1 = load(pose.q_cm1), q_s = load(pose.q_s);
  Lanes ux[4], uy[4], vx[4], vy[4];  // the displacements of P's and Q's vertices
  for (int k = 0; k < 4; ++k) {
    const Lanes rx = load(offset.px[k]), ry = load(offset.py[k]);
    ux[k] = p_ux + p_cm1 * rx - p_s * ry, uy[k] = p_uy + p_s * rx + p_cm1 * ry;
    const Lanes sx = load(offset.qx[k]), sy = load(offset.qy[k]);
    vx[k] = q_ux + q_cm1 * sx - q_s * sy, vy[k] = q_uy + q_s * sx + q_cm1 * sy;
  }
  for (int k = 0; k < 4; ++k) {
    store(out.px[k], load(ref.px[k]) + (ux[k] - ux[0]));
    store(out.py[k], load(ref.py[k]) + (uy[k] - uy[0]));
    store(out.qx[k], load(ref.qx[k]) + (vx[k] - ux[0]));
    store(out.qy[k], load(ref.qy[k]) + (vy[k] - uy[0]));
  }
  store(out.ox, load(ref.ox) + ux[0]), store(out.oy, load(ref.oy) + uy[0]);
}

void quad_overlaps(const QuadPairs& in, QuadOverlaps& out) {
  Lanes px[4], py[4], qx[4], qy[4];
  for (int k = 0; k < 4; ++k) {
    px[k] = load(in.px[k]), py[k] = load(in.py[k]);
    qx[k] = load(in.qx[k]), qy[k] = load(in.qy[k]);
  }
  // dq[j][k]: P's vertex k against Q's side line j; dp[i][l]: Q's vertex l against P's line i.
  // Differences first, as rigid_contact.cpp's clipping takes them.
  Lanes dq[4][4], dp[4][4];
  for (int j = 0; j < 4; ++j) {
    const int j1 = (j + 1) & 3;
    const Lanes ex = qx[j1] - qx[j], ey = qy[j1] - qy[j];
    for (int k = 0; k < 4; ++k) dq[j][k] = ex * (py[k] - qy[j]) - ey * (px[k] - qx[j]);
    const Lanes fx = px[j1] - px[j], fy = py[j1] - py[j];
    for (int l = 0; l < 4; ++l) dp[j][l] = fx * (qy[l] - py[j]) - fy * (qx[l] - px[j]);
  }
  Piece pe[4], qe[4];
  for (int k = 0; k < 4; ++k) {
    const int k1 = (k + 1) & 3;
    Lanes da[4], db[4];
    for (int j = 0; j < 4; ++j) da[j] = dq[j][k], db[j] = dq[j][k1];
    pe[k] = clip_edge(px[k], py[k], px[k1], py[k1], da, db, false);
    for (int j = 0; j < 4; ++j) da[j] = dp[j][k], db[j] = dp[j][k1];
    qe[k] = clip_edge(qx[k], qy[k], qx[k1], qy[k1], da, db, true);
  }
  // The reference point: the start of the first kept piece.
  const Lanes zero = splat(0.0), one = splat(1.0);
  Lanes rx = zero, ry = zero;
  for (int k = 3; k >= 0; --k)
    rx = select(qe[k].kept, qe[k].sx, rx), ry = select(qe[k].kept, qe[k].sy, ry);
  for (int k = 3; k >= 0; --k)
    rx = select(pe[k].kept, pe[k].sx, rx), ry = select(pe[k].kept, pe[k].sy, ry);
  // Green's sums over the kept pieces; n = (N_P - N_Q) / 2.
  Lanes a2 = zero, mx = zero, my = zero, nx = zero, ny = zero;
  auto add = [&](const Piece& s, double w) {
    const Lanes x0 = s.sx - rx, y0 = s.sy - ry, x1 = s.ex - rx, y1 = s.ey - ry;
    const Lanes c = select(s.kept, x0 * y1 - y0 * x1, zero);
    a2 += c;
    mx += (x0 + x1) * c;
    my += (y0 + y1) * c;
    nx += select(s.kept, w * (y1 - y0), zero);
    ny -= select(s.kept, w * (x1 - x0), zero);
  };
  for (int k = 0; k < 4; ++k) add(pe[k], 0.5);
  for (int k = 0; k < 4; ++k) add(qe[k], -0.5);
  // Crossing points: a kept piece's start that does not continue the previous edge's piece
  // at P's vertex, its end that does not run on into the next one's.
  Lanes cx = zero, cy = zero, count = zero;
  for (int k = 0; k < 4; ++k) {
    const Piece &prev = pe[(k + 3) & 3], &cur = pe[k], &next = pe[(k + 1) & 3];
    const Mask joined_start = (cur.t0 == zero) & prev.kept & (prev.t1 == one);
    const Mask joined_end = (cur.t1 == one) & next.kept & (next.t0 == zero);
    const Mask start = cur.kept & ~joined_start, end = cur.kept & ~joined_end;
    cx += select(start, cur.sx, zero) + select(end, cur.ex, zero);
    cy += select(start, cur.sy, zero) + select(end, cur.ey, zero);
    count += select(start, one, zero) + select(end, one, zero);
  }
  const Lanes chord_sq = nx * nx + ny * ny;
  // Without a crossing one piece holds the other whole: no chord, no joint.
  const Mask on = (a2 > zero) & (chord_sq > zero) & (count > zero);
  alignas(64) double root[kQuadLanes];
  store(root, chord_sq);
  // A square root per lane, inline: the file is built without errno for the math functions
  // (CMakeLists.txt), which a sum of squares never needs, so no lane calls the library.
  for (int l = 0; l < kQuadLanes; ++l) root[l] = __builtin_sqrt(root[l]);
  const Lanes chord = load(root);
  const Lanes safe_a2 = select(on, a2, one), safe_chord = select(on, chord, one);
  const Lanes third = one / (splat(3.0) * safe_a2), inv_chord = one / safe_chord;
  const Lanes ox = load(in.ox), oy = load(in.oy);
  const Lanes gx = ox + (rx + mx * third), gy = oy + (ry + my * third);
  const Mask two = count == splat(2.0);
  store(out.area, splat(0.5) * a2);
  store(out.gx, gx), store(out.gy, gy);
  store(out.nx, nx * inv_chord), store(out.ny, ny * inv_chord);
  store(out.chord, chord);
  store(out.mx, select(two, ox + splat(0.5) * cx, gx));
  store(out.my, select(two, oy + splat(0.5) * cy, gy));
  std::memcpy(out.on, &on, sizeof on);
}

}  // namespace voussoir
