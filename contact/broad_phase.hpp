#pragma once
// Broad phase: Munjiza-Andrews NBS ("no binary search") contact detection.
//
// Participants. A triangle takes part when it has an edge on its block's boundary
// (Triangles::boundary != 0): a triangle with no boundary edge is covered by its neighbours
// and can never be the first thing another block touches. Triangles of one block never pair,
// and two triangles of fixed blocks never pair (docs/design.md "Contact": no contact search between
// fixed blocks). Participants are kept in ascending triangle id order; "local index" below
// means the position in that list.
//
// Candidate criterion (the exact contract; brute_force_candidates uses the same one). With
// b the buffer [m], each participant gets its current axis-aligned bounding box inflated by
// b/2 on every side:  lo = min(node) - b/2,  hi = max(node) + b/2.  Participants i and j are a
// candidate pair when they are a valid pair (above) and the closed inflated boxes overlap on
// both axes:  lo_i <= hi_j  and  lo_j <= hi_i  in x and in y.
//
// Laziness. If i and j are not candidates at a detection, their inflated boxes are apart by
// more than 0 on some axis, so their true boxes are apart by more than b. Until every node has
// moved by at most b/2 (Euclidean, which bounds the move of every box side) the true boxes stay
// apart, so no contact can be missed. needs_detection() tests exactly that, on the nodes of the
// participants of free blocks (fixed nodes never move).
//
// Default buffer (ContactParams::buffer = 0): kDefaultBufferFraction x the smallest bounding
// box extent (max of width and height) over the participants. Rationale: the extent, unlike
// the height, does not collapse for slivers; 0.1 of the smallest element keeps the candidate
// list close to the true neighbour list while a block moving at 1 m/s with dt = 1e-6 s
// re-detects only every ~1e3 steps for 2 cm elements.
//
// NBS grid (Munjiza & Andrews 1998, "NBS contact detection algorithm for bodies of similar
// size", IJNME 43). Cell size d = largest inflated box extent over the participants of free
// blocks (times 1 + 1e-9 so that round-off in the cell index can never separate two
// overlapping boxes by two cells). Each participant is mapped to the cell of its box's lower
// corner: if boxes i and j overlap then |lo_i - lo_j| <= d on each axis, so their cells differ
// by at most one in x and in y and only the 3 x 3 neighbourhood needs checking. Following NBS,
// participants are first linked into row lists (head_row / next_row, the flat LAMMPS nbin
// layout), then the rows are swept in order; for the current row and the one below it the
// column lists (head_col / next_col) are built, and each participant is checked against its own
// cell (later entries only), the cell to its right, and the three cells of the row below: every
// neighbouring cell pair is visited exactly once. Head arrays are reset by walking the lists,
// never by clearing them, so a detection costs O(participants + rows) time with
// O(participants + rows + columns) memory, whatever the size of the empty space in the domain.
// The number of rows/columns is capped at 2 n + 64 by enlarging the cell when the domain is
// very elongated or blocks have flown apart (larger cells stay correct, only slower).
//
// Large fixed triangles. Supports are often meshed much coarser than the free blocks; putting
// a 5 m ground triangle into the grid would make every cell 5 m wide and the sweep quadratic.
// Participants of fixed blocks whose inflated extent exceeds d are therefore kept out of the
// grid and tested directly against every free participant (cost: large x free, with "large"
// being a handful of support triangles). Limitation (documented, not handled): free blocks
// meshed at very different sizes share the cell of the largest one.
//
// Output: candidate pairs (a, b) of triangle ids with a < b, sorted by (a, b), by a two-pass
// counting sort (linear). The order does not depend on the sweep or on any thread count.

#include <cstdint>
#include <vector>

#include "core/model.hpp"

namespace voussoir {

// Fraction of the smallest participant extent used as the default buffer (dimensionless,
// typical 0.1-0.2).
inline constexpr double kDefaultBufferFraction = 0.1;

struct IndexPair {
  Index a = 0, b = 0;  // triangle ids, a < b
  friend bool operator==(const IndexPair&, const IndexPair&) = default;
};

// Triangles that take part in contact, in ascending id order, with what the pair filter needs.
struct Participants {
  std::vector<Index> tri;           // triangle id
  std::vector<Index> block;         // owning block
  std::vector<std::uint8_t> fixed;  // 1 when the block is fixed
  std::vector<Index> free_nodes;    // distinct nodes of participants of free blocks and of
                                    // supports that move (Block::prescribed), ascending

  Index size() const { return static_cast<Index>(tri.size()); }
};

// Chooses the participants of a model (boundary triangles of blocks that can touch another
// block). Blocks can touch only if at least one of the two is free, so when every block is
// fixed the list is empty.
Participants select_participants(const Model& model);

// Default buffer [m] of a model: kDefaultBufferFraction x the smallest participant extent in
// the current configuration (0 if there are no participants).
double default_buffer(const Model& model, const Participants& parts);

class BroadPhase {
 public:
  // Selects participants and sizes the work arrays. buffer > 0 [m].
  void setup(const Model& model, double buffer);

  // True before the first detection and when some participant node of a free block has moved
  // by more than buffer/2 since the last detection.
  bool needs_detection(const Nodes& nodes) const;

  // Rebuilds `out` (sorted candidate pairs) from the current node positions and records the
  // positions for needs_detection. Reuses all internal buffers (no allocation once sized).
  void detect(const Nodes& nodes, std::vector<IndexPair>& out);

  double buffer() const { return buffer_; }
  double cell_size() const { return cell_; }
  const Participants& participants() const { return parts_; }

 private:
  // Inflated boxes of every participant (local index) from the current positions.
  void compute_boxes(const Nodes& nodes);
  void emit_if_candidate(Index i, Index j);

  Participants parts_;
  std::vector<Index> n0_, n1_, n2_;  // nodes of each participant (local index)
  double buffer_ = 0.0;
  double cell_ = 0.0;
  bool detected_ = false;

  // Positions of free participant nodes at the last detection (same order as free_nodes).
  std::vector<double> ref_x_, ref_y_;

  // Work arrays (local index).
  std::vector<double> lo_x_, lo_y_, hi_x_, hi_y_;
  std::vector<Index> cell_x_, cell_y_;
  std::vector<Index> head_row_, next_row_;
  std::vector<Index> head_col_cur_, head_col_prev_, next_col_;
  std::vector<Index> large_, grid_;   // large fixed participants; participants in the grid
  std::vector<Index> free_local_;     // participants of free blocks
  std::vector<IndexPair> raw_, tmp_;  // local-index pairs before sorting
  std::vector<Index> count_;
};

// Reference: every participant pair tested with the same criterion (O(n^2)); for tests.
std::vector<IndexPair> brute_force_candidates(const Model& model, double buffer);

}  // namespace voussoir
