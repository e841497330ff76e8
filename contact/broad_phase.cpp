#include "contact/broad_phase.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/parallel.hpp"

namespace voussoir {

namespace {

struct Box {
  double lo_x, lo_y, hi_x, hi_y;
};

// Current bounding box of triangle (i0, i1, i2) inflated by half_buffer on every side.
inline Box inflated_box(const Nodes& n, Index i0, Index i1, Index i2, double half_buffer) {
  Box b;
  b.lo_x = std::min({n.x[i0], n.x[i1], n.x[i2]}) - half_buffer;
  b.hi_x = std::max({n.x[i0], n.x[i1], n.x[i2]}) + half_buffer;
  b.lo_y = std::min({n.y[i0], n.y[i1], n.y[i2]}) - half_buffer;
  b.hi_y = std::max({n.y[i0], n.y[i1], n.y[i2]}) + half_buffer;
  return b;
}

// The candidate criterion on two inflated boxes (closed intervals on both axes).
inline bool boxes_overlap(double alx, double aly, double ahx, double ahy, double blx, double bly,
                          double bhx, double bhy) {
  return alx <= bhx && blx <= ahx && aly <= bhy && bly <= ahy;
}

}  // namespace

Participants select_participants(const Model& model) {
  Participants p;
  Index free_blocks = 0;
  for (const Block& b : model.blocks) free_blocks += b.fixed ? 0 : 1;
  // Contact needs two blocks, one of them free.
  if (free_blocks == 0 || model.blocks.size() < 2) return p;
  const Triangles& t = model.tris;
  for (Index e = 0; e < t.size(); ++e) {
    if (t.boundary[e] == 0) continue;
    const bool fixed = model.blocks[t.block[e]].fixed;
    p.tri.push_back(e);
    p.block.push_back(t.block[e]);
    p.fixed.push_back(fixed ? 1 : 0);
    // The nodes watched against the buffer: those of free blocks and of supports that move.
    if (!fixed || model.blocks[t.block[e]].prescribed) {
      p.free_nodes.push_back(t.n0[e]);
      p.free_nodes.push_back(t.n1[e]);
      p.free_nodes.push_back(t.n2[e]);
    }
  }
  std::sort(p.free_nodes.begin(), p.free_nodes.end());
  p.free_nodes.erase(std::unique(p.free_nodes.begin(), p.free_nodes.end()), p.free_nodes.end());
  return p;
}

double default_buffer(const Model& model, const Participants& parts) {
  double smallest = 0.0;
  bool any = false;
  for (Index i = 0; i < parts.size(); ++i) {
    const Index e = parts.tri[i];
    const Box b =
        inflated_box(model.nodes, model.tris.n0[e], model.tris.n1[e], model.tris.n2[e], 0.0);
    const double extent = std::max(b.hi_x - b.lo_x, b.hi_y - b.lo_y);
    smallest = any ? std::min(smallest, extent) : extent;
    any = true;
  }
  return kDefaultBufferFraction * smallest;
}

void BroadPhase::setup(const Model& model, double buffer) {
  parts_ = select_participants(model);
  buffer_ = buffer;
  detected_ = false;
  const Index n = parts_.size();
  n0_.resize(n);
  n1_.resize(n);
  n2_.resize(n);
  free_local_.clear();
  for (Index i = 0; i < n; ++i) {
    const Index e = parts_.tri[i];
    n0_[i] = model.tris.n0[e];
    n1_[i] = model.tris.n1[e];
    n2_[i] = model.tris.n2[e];
    if (!parts_.fixed[i]) free_local_.push_back(i);
  }
  ref_x_.assign(parts_.free_nodes.size(), 0.0);
  ref_y_.assign(parts_.free_nodes.size(), 0.0);
  for (auto* v : {&lo_x_, &lo_y_, &hi_x_, &hi_y_}) v->assign(n, 0.0);
  for (auto* v : {&cell_x_, &cell_y_, &next_row_, &next_col_}) v->assign(n, -1);
  count_.assign(n + 1, 0);
  grid_.reserve(n);
  large_.reserve(n);
  head_row_.clear();
  head_col_cur_.clear();
  head_col_prev_.clear();
}

bool BroadPhase::needs_detection(const Nodes& nodes) const {
  if (!detected_) return true;
  const double limit2 = 0.25 * buffer_ * buffer_;  // (b/2)^2
  const Index m = static_cast<Index>(parts_.free_nodes.size());
  const Index* id = parts_.free_nodes.data();
  const double *x = nodes.x.data(), *y = nodes.y.data();
  const double *rx = ref_x_.data(), *ry = ref_y_.data();
  if (m < kParallelNodes || !threads_available()) {
    for (Index k = 0; k < m; ++k) {
      const double dx = x[id[k]] - rx[k], dy = y[id[k]] - ry[k];
      if (dx * dx + dy * dy > limit2) return true;
    }
    return false;
  }
  // Large models, every step: the nodes on the threads (a yes/no answer, the same for any
  // split; no early exit, detection is rare).
  bool moved = false;
#pragma omp parallel for schedule(static) reduction(|| : moved)
  for (Index k = 0; k < m; ++k) {
    const double dx = x[id[k]] - rx[k], dy = y[id[k]] - ry[k];
    moved = moved | (dx * dx + dy * dy > limit2);
  }
  return moved;
}

void BroadPhase::compute_boxes(const Nodes& nodes) {
  const double half = 0.5 * buffer_;
  for (Index i = 0; i < parts_.size(); ++i) {
    const Box b = inflated_box(nodes, n0_[i], n1_[i], n2_[i], half);
    lo_x_[i] = b.lo_x;
    lo_y_[i] = b.lo_y;
    hi_x_[i] = b.hi_x;
    hi_y_[i] = b.hi_y;
  }
}

inline void BroadPhase::emit_if_candidate(Index i, Index j) {
  if (parts_.block[i] == parts_.block[j]) return;
  if (parts_.fixed[i] && parts_.fixed[j]) return;
  if (!boxes_overlap(lo_x_[i], lo_y_[i], hi_x_[i], hi_y_[i], lo_x_[j], lo_y_[j], hi_x_[j],
                     hi_y_[j]))
    return;
  raw_.push_back(i < j ? IndexPair{i, j} : IndexPair{j, i});
}

void BroadPhase::detect(const Nodes& nodes, std::vector<IndexPair>& out) {
  const Index n = parts_.size();
  raw_.clear();
  out.clear();
  compute_boxes(nodes);

  // Cell size from the free participants; fixed ones larger than that stay out of the grid.
  double dmax = 0.0;
  for (Index i : free_local_)
    dmax = std::max(dmax, std::max(hi_x_[i] - lo_x_[i], hi_y_[i] - lo_y_[i]));
  grid_.clear();
  large_.clear();
  if (!free_local_.empty()) {
    for (Index i = 0; i < n; ++i) {
      const double extent = std::max(hi_x_[i] - lo_x_[i], hi_y_[i] - lo_y_[i]);
      (parts_.fixed[i] && extent > dmax ? large_ : grid_).push_back(i);
    }
  }

  if (!grid_.empty()) {
    double ox = lo_x_[grid_[0]], oy = lo_y_[grid_[0]], mx = ox, my = oy;
    for (Index i : grid_) {
      ox = std::min(ox, lo_x_[i]);
      oy = std::min(oy, lo_y_[i]);
      mx = std::max(mx, lo_x_[i]);
      my = std::max(my, lo_y_[i]);
    }
    const Index cap = 2 * static_cast<Index>(grid_.size()) + 64;
    cell_ = dmax * (1.0 + 1e-9);
    cell_ = std::max({cell_, (mx - ox) / (cap - 1), (my - oy) / (cap - 1)});
    if (!(cell_ > 0.0)) cell_ = 1.0;  // all boxes degenerate: one cell
    const double inv = 1.0 / cell_;
    auto index_of = [inv, cap](double v) {
      // Clamping is monotone and 1-Lipschitz on the integers: neighbours stay neighbours.
      return std::min(static_cast<Index>(std::floor(v * inv)), cap - 1);
    };
    const Index ncol = index_of(mx - ox) + 1, nrow = index_of(my - oy) + 1;
    if (static_cast<Index>(head_row_.size()) < nrow) head_row_.resize(nrow, -1);
    if (static_cast<Index>(head_col_cur_.size()) < ncol) {
      head_col_cur_.resize(ncol, -1);
      head_col_prev_.resize(ncol, -1);
    }
    for (Index i : grid_) {
      cell_x_[i] = index_of(lo_x_[i] - ox);
      cell_y_[i] = index_of(lo_y_[i] - oy);
    }
    // Row lists (pushed in descending order so each list runs in ascending local index).
    for (auto it = grid_.rbegin(); it != grid_.rend(); ++it) {
      next_row_[*it] = head_row_[cell_y_[*it]];
      head_row_[cell_y_[*it]] = *it;
    }
    Index* col_cur = head_col_cur_.data();
    Index* col_prev = head_col_prev_.data();
    bool prev_filled = false;  // col_prev holds the column lists of row iy - 1
    for (Index iy = 0; iy < nrow; ++iy) {
      const Index h = head_row_[iy];
      if (h < 0) {
        if (prev_filled)
          for (Index j = head_row_[iy - 1]; j >= 0; j = next_row_[j]) col_prev[cell_x_[j]] = -1;
        prev_filled = false;
        continue;
      }
      for (Index i = h; i >= 0; i = next_row_[i]) {
        next_col_[i] = col_cur[cell_x_[i]];
        col_cur[cell_x_[i]] = i;
      }
      for (Index i = h; i >= 0; i = next_row_[i]) {
        const Index cx = cell_x_[i];
        for (Index j = next_col_[i]; j >= 0; j = next_col_[j]) emit_if_candidate(i, j);
        if (cx + 1 < ncol)
          for (Index j = col_cur[cx + 1]; j >= 0; j = next_col_[j]) emit_if_candidate(i, j);
        if (prev_filled) {
          for (Index c = std::max<Index>(cx - 1, 0); c <= std::min<Index>(cx + 1, ncol - 1); ++c)
            for (Index j = col_prev[c]; j >= 0; j = next_col_[j]) emit_if_candidate(i, j);
        }
      }
      if (prev_filled)
        for (Index j = head_row_[iy - 1]; j >= 0; j = next_row_[j]) col_prev[cell_x_[j]] = -1;
      std::swap(col_cur, col_prev);
      prev_filled = true;
    }
    if (prev_filled)
      for (Index j = head_row_[nrow - 1]; j >= 0; j = next_row_[j]) col_prev[cell_x_[j]] = -1;
    for (Index i : grid_) head_row_[cell_y_[i]] = -1;
  }

  // Large fixed participants against every free participant.
  for (Index l : large_)
    for (Index f : free_local_) emit_if_candidate(l, f);

  // Two-pass counting sort (by b, then stably by a): sorted by (a, b) in linear time.
  const std::size_t np = raw_.size();
  tmp_.resize(np);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<IndexPair>& from = pass == 0 ? raw_ : tmp_;
    std::vector<IndexPair>& to = pass == 0 ? tmp_ : raw_;
    std::fill(count_.begin(), count_.end(), 0);
    for (const IndexPair& p : from) ++count_[(pass == 0 ? p.b : p.a) + 1];
    for (Index k = 0; k < n; ++k) count_[k + 1] += count_[k];
    for (const IndexPair& p : from) to[count_[pass == 0 ? p.b : p.a]++] = p;
  }
  out.resize(np);
  for (std::size_t k = 0; k < np; ++k) out[k] = {parts_.tri[raw_[k].a], parts_.tri[raw_[k].b]};

  for (std::size_t k = 0; k < parts_.free_nodes.size(); ++k) {
    ref_x_[k] = nodes.x[parts_.free_nodes[k]];
    ref_y_[k] = nodes.y[parts_.free_nodes[k]];
  }
  detected_ = true;
}

std::vector<IndexPair> brute_force_candidates(const Model& model, double buffer) {
  const Participants p = select_participants(model);
  const Triangles& t = model.tris;
  std::vector<Box> box(p.size());
  for (Index i = 0; i < p.size(); ++i) {
    const Index e = p.tri[i];
    box[i] = inflated_box(model.nodes, t.n0[e], t.n1[e], t.n2[e], 0.5 * buffer);
  }
  std::vector<IndexPair> out;
  for (Index i = 0; i < p.size(); ++i)
    for (Index j = i + 1; j < p.size(); ++j) {
      if (p.block[i] == p.block[j] || (p.fixed[i] && p.fixed[j])) continue;
      const Box &a = box[i], &b = box[j];
      if (boxes_overlap(a.lo_x, a.lo_y, a.hi_x, a.hi_y, b.lo_x, b.lo_y, b.hi_x, b.hi_y))
        out.push_back({p.tri[i], p.tri[j]});
    }
  return out;
}

}  // namespace voussoir
