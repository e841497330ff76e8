// A peer code on voussoir's own decks: Box2D 2.4 (Debian's libbox2d-dev), timed side by side
// with the rigid step (docs/peers.md). Not part of the product: built only where Box2D is found
// (CMakeLists.txt), run by scripts/peer_box2d.
//
// What it does. The deck is read and its scene built by voussoir_lib exactly as `voussoir run`
// builds it (make_simulation: rigid blocks with the minimal outlines their contact uses). Each
// block becomes one Box2D body placed at the block's centroid: static for a fixed block,
// dynamic for a free one, with polygon fixtures of the deck's friction (Box2D mixes two
// fixtures' friction as sqrt(mu_a mu_b) = mu), restitution 0, and a density that gives the
// block its deck mass (kg per metre of out-of-plane thickness times model.out_of_plane, as
// voussoir's Block::mass). Gravity (lambda g, -g) with the deck's g; lambda from --lambda.
//
// The two models differ, and the comparison is of cost only:
//   - Box2D's contacts are impulses: a sequential-impulse solver of non-penetration and
//     Coulomb friction (8 velocity and 3 position iterations by default), no joint stiffness;
//     voussoir's joints are Winkler springs kn, ks integrated by explicit central differences
//     at a step set by the stiffest joint mode (docs/rigid.md).
//   - Box2D polygons are convex with at most b2_maxPolygonVertices (8) vertices. An outline that
//     is not convex or has more vertices is cut into convex pieces: voussoir's own ear clipping
//     (mesh/minimal.hpp), then adjacent pieces merged while the union stays convex and within
//     8 vertices (Hertel-Mehlhorn). The pieces of one body never collide with each other.
//   - Box2D polygons carry a skin of b2_polygonRadius (0.01 m) and its position solver lets
//     two skins overlap by b2_linearSlop (0.005 m): two outlines touching at the start would
//     be pushed 0.015 m apart, and a 12-joint arch would grow by 0.18 m. Every piece is
//     therefore shrunk by --shrink (default b2_polygonRadius - b2_linearSlop / 2 = 0.0075 m,
//     each edge moved inward), so that the skins at rest sit on the deck's joints; --shrink 0
//     keeps the outlines as they are. The mass stays the deck's (the density is set on the
//     shrunk area); the moment of inertia is the shrunk shape's.
//   - Sleeping is off (`--sleep` turns it on): a sleeping island costs nothing, and voussoir
//     has no such state, so the cost per step would measure how soon the bodies doze.
//
// Timing: steady_clock around the calls of b2World::Step only; the contacts are counted
// between timed chunks of about 0.01 s of simulated time. "Touching contacts" are Box2D's
// b2Contacts with IsTouching() (one per pair of touching fixtures); "touching body pairs" merges
// those of the same two bodies, the unit voussoir counts (its touching block pairs).
//
// Run: build/peer_box2d cases/church_b.toml [--dt 1e-4] [--end 5] [--json FILE]
#include <box2d/box2d.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "engine/setup.hpp"
#include "io/deck.hpp"
#include "mesh/minimal.hpp"

using namespace voussoir;

namespace {

using Polygon = std::vector<Vec2>;

double signed_area(const Polygon& p) {
  double a = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) a += cross(p[i], p[(i + 1) % p.size()]);
  return 0.5 * a;
}

Vec2 centroid(const Polygon& p) {
  double a = 0.0, cx = 0.0, cy = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2 u = p[i], v = p[(i + 1) % p.size()];
    const double c = cross(u, v);
    a += c;
    cx += (u.x + v.x) * c;
    cy += (u.y + v.y) * c;
  }
  return {cx / (3.0 * a), cy / (3.0 * a)};
}

// Drops the vertices where the outline goes straight on (|sin| of the turn below 1e-9).
Polygon drop_collinear(const Polygon& p) {
  Polygon out;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = p[(i + n - 1) % n], b = p[i], c = p[(i + 1) % n];
    const Vec2 u{b.x - a.x, b.y - a.y}, v{c.x - b.x, c.y - b.y};
    if (std::abs(cross(u, v)) > 1e-9 * norm(u) * norm(v)) out.push_back(b);
  }
  return out;
}

// Counter-clockwise and convex (no turn to the right)?
bool is_convex(const Polygon& p) {
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = p[i], b = p[(i + 1) % n], c = p[(i + 2) % n];
    const Vec2 u{b.x - a.x, b.y - a.y}, v{c.x - b.x, c.y - b.y};
    if (cross(u, v) < -1e-12 * norm(u) * norm(v)) return false;
  }
  return true;
}

// Convex pieces of a simple counter-clockwise outline, each of at most kMax vertices: the
// ear-clipped triangles, merged across their shared diagonals while the union stays convex.
std::vector<Polygon> convex_pieces(const Polygon& outline, std::size_t kMax) {
  const Polygon p = drop_collinear(outline);
  if (p.size() <= kMax && is_convex(p)) return {p};
  std::vector<std::vector<Index>> pieces;
  for (const auto& t : ear_clip(p)) pieces.push_back({t[0], t[1], t[2]});
  const auto as_polygon = [&](const std::vector<Index>& ids) {
    Polygon q;
    for (Index i : ids) q.push_back(p[i]);
    return q;
  };
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t a = 0; a < pieces.size() && !merged; ++a) {
      for (std::size_t b = a + 1; b < pieces.size() && !merged; ++b) {
        const auto& A = pieces[a];
        const auto& B = pieces[b];
        // A shared diagonal: i -> j in A is j -> i in B.
        for (std::size_t ia = 0; ia < A.size() && !merged; ++ia) {
          const Index i = A[ia], j = A[(ia + 1) % A.size()];
          const auto jb = std::find(B.begin(), B.end(), j);
          if (jb == B.end() || B[(jb - B.begin() + 1) % B.size()] != i) continue;
          // The union: A from j round to i, then B from i round to j, without the ends.
          std::vector<Index> u;
          for (std::size_t k = 0; k < A.size(); ++k) u.push_back(A[(ia + 1 + k) % A.size()]);
          const std::size_t ib = (jb - B.begin() + 1) % B.size();  // position of i in B
          for (std::size_t k = 1; k + 1 < B.size(); ++k) u.push_back(B[(ib + k) % B.size()]);
          const Polygon q = drop_collinear(as_polygon(u));
          if (q.size() > kMax || !is_convex(as_polygon(u))) continue;
          std::vector<Index> kept;
          for (Index id : u) {
            if (std::find_if(q.begin(), q.end(),
                             [&](Vec2 v) { return v.x == p[id].x && v.y == p[id].y; }) != q.end())
              kept.push_back(id);
          }
          pieces[a] = kept;
          pieces.erase(pieces.begin() + static_cast<std::ptrdiff_t>(b));
          merged = true;
        }
      }
    }
  }
  std::vector<Polygon> out;
  for (const auto& ids : pieces) out.push_back(as_polygon(ids));
  return out;
}

// The convex counter-clockwise polygon with every edge moved inward by s; empty when it
// vanishes (a piece thinner than 2 s) or loses an edge.
Polygon shrink(const Polygon& p, double s) {
  if (s == 0.0) return p;
  const std::size_t n = p.size();
  std::vector<Vec2> normal(n);  // inward unit normal of edge i (p_i -> p_i+1)
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 e{p[(i + 1) % n].x - p[i].x, p[(i + 1) % n].y - p[i].y};
    const double l = norm(e);
    normal[i] = {-e.y / l, e.x / l};
  }
  Polygon out(n);
  for (std::size_t i = 0; i < n; ++i) {
    // Vertex i meets edges i - 1 and i: dot(n_k, x - p_i) = s for both.
    const Vec2 a = normal[(i + n - 1) % n], b = normal[i];
    const double det = cross(a, b);
    out[i] = {p[i].x + s * (b.y - a.y) / det, p[i].y + s * (a.x - b.x) / det};
  }
  // Each shrunk edge keeps its direction (or the piece has folded).
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 e0{p[(i + 1) % n].x - p[i].x, p[(i + 1) % n].y - p[i].y};
    const Vec2 e1{out[(i + 1) % n].x - out[i].x, out[(i + 1) % n].y - out[i].y};
    if (dot(e0, e1) <= 0.0 || norm(e1) < b2_linearSlop) return {};
  }
  return out;
}

struct Peer {
  b2World world{b2Vec2(0.0f, -9.81f)};
  std::vector<b2Body*> free_bodies;
  std::vector<b2Vec2> start;  // initial position of each free body [m]
  int bodies = 0, fixtures = 0, split_blocks = 0;
};

// One Box2D body per block of the model; throws when a piece vanishes under the shrink.
void build_world(const Model& model, const Config& config, double shrink_by, double lambda,
                 Peer& peer) {
  const double g = config.load.gravity;
  peer.world.SetGravity(b2Vec2(static_cast<float>(lambda * g), static_cast<float>(-g)));
  for (std::size_t k = 0; k < model.blocks.size(); ++k) {
    const Block& blk = model.blocks[k];
    Polygon outline = blk.polygon;
    if (signed_area(outline) < 0.0) std::reverse(outline.begin(), outline.end());
    const Vec2 c = centroid(outline);
    std::vector<Polygon> pieces;
    for (const Polygon& piece : convex_pieces(outline, b2_maxPolygonVertices)) {
      Polygon local;
      for (Vec2 v : piece) local.push_back({v.x - c.x, v.y - c.y});
      Polygon shrunk = shrink(local, shrink_by);
      if (shrunk.empty())
        throw std::runtime_error("block " + std::to_string(k) + ": a convex piece of " +
                                 std::to_string(piece.size()) +
                                 " vertices vanishes when shrunk by " + std::to_string(shrink_by) +
                                 " m (try --shrink 0)");
      pieces.push_back(std::move(shrunk));
    }
    if (pieces.size() > 1) ++peer.split_blocks;
    double area = 0.0;
    for (const Polygon& q : pieces) area += signed_area(q);
    b2BodyDef def;
    def.type = blk.fixed ? b2_staticBody : b2_dynamicBody;
    def.position.Set(static_cast<float>(c.x), static_cast<float>(c.y));
    b2Body* body = peer.world.CreateBody(&def);
    for (const Polygon& q : pieces) {
      std::array<b2Vec2, b2_maxPolygonVertices> v{};
      for (std::size_t i = 0; i < q.size(); ++i)
        v[i].Set(static_cast<float>(q[i].x), static_cast<float>(q[i].y));
      b2PolygonShape shape;
      shape.Set(v.data(), static_cast<int32>(q.size()));
      if (shape.m_count != static_cast<int32>(q.size()))
        throw std::runtime_error("block " + std::to_string(k) + ": Box2D kept " +
                                 std::to_string(shape.m_count) + " of a piece's " +
                                 std::to_string(q.size()) + " vertices");
      b2FixtureDef fd;
      fd.shape = &shape;
      fd.density = static_cast<float>(blk.mass / area);  // the deck's mass on the shrunk area
      fd.friction = static_cast<float>(config.contact.friction);
      fd.restitution = 0.0f;
      body->CreateFixture(&fd);
      ++peer.fixtures;
    }
    ++peer.bodies;
    if (!blk.fixed) {
      peer.free_bodies.push_back(body);
      peer.start.push_back(body->GetPosition());
    }
  }
}

struct Contacts {
  int touching = 0;    // touching b2Contacts (fixture pairs)
  int body_pairs = 0;  // distinct body pairs among them
  int points = 0;      // manifold points of the touching contacts
};

Contacts count_contacts(b2World& world) {
  Contacts c;
  std::set<std::pair<const b2Body*, const b2Body*>> pairs;
  for (b2Contact* ct = world.GetContactList(); ct; ct = ct->GetNext()) {
    if (!ct->IsTouching()) continue;
    ++c.touching;
    c.points += ct->GetManifold()->pointCount;
    const b2Body* a = ct->GetFixtureA()->GetBody();
    const b2Body* b = ct->GetFixtureB()->GetBody();
    pairs.insert(a < b ? std::make_pair(a, b) : std::make_pair(b, a));
  }
  c.body_pairs = static_cast<int>(pairs.size());
  return c;
}

// Largest displacement of a free body's reference point (the block's centroid) [m], and the
// largest speed of a free body [m/s].
std::pair<double, double> motion(const Peer& peer) {
  double d = 0.0, v = 0.0;
  for (std::size_t i = 0; i < peer.free_bodies.size(); ++i) {
    const b2Vec2 p = peer.free_bodies[i]->GetPosition() - peer.start[i];
    d = std::max(d, static_cast<double>(p.Length()));
    v = std::max(v, static_cast<double>(peer.free_bodies[i]->GetLinearVelocity().Length()));
  }
  return {d, v};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Box2D 2.4 on a voussoir deck: cost per step and per contact (docs/peers.md)"};
  std::string deck, json_path;
  std::vector<std::string> sets;
  double dt = 1.0 / 60.0, end = 5.0, lambda = 0.0;
  double shrink_by = b2_polygonRadius - 0.5 * b2_linearSlop;
  double stand = 0.05;
  int velocity_iterations = 8, position_iterations = 3;
  bool sleep = false;
  app.add_option("deck", deck, "voussoir deck (TOML)")->required();
  app.add_option("--set", sets, "deck override KEY=VALUE, as voussoir's --set");
  app.add_option("--dt", dt, "time step [s] (Box2D's usual 1/60)");
  app.add_option("--end", end, "simulated time [s]; the state is also reported at 1 s");
  app.add_option("--velocity-iterations", velocity_iterations);
  app.add_option("--position-iterations", position_iterations);
  app.add_option("--lambda", lambda, "horizontal body load, x g (the tilt of a capacity trial)");
  app.add_option("--shrink", shrink_by, "inward offset of every piece [m] (see the file's head)");
  app.add_option("--stand", stand,
                 "a structure stands while no free block has moved more than this [m]");
  app.add_flag("--sleep", sleep, "let resting bodies sleep (off: every body is stepped)");
  app.add_option("--json", json_path, "write the figures to this file");
  CLI11_PARSE(app, argc, argv);

  try {
    const Config config = load_deck(deck, sets);
    SetupInfo info;
    const Simulation sim = make_simulation(config, &info);
    Peer peer;
    build_world(sim.model, config, shrink_by, lambda, peer);
    peer.world.SetAllowSleeping(sleep);

    const long long steps = std::llround(end / dt);
    const long long chunk = std::max(1LL, std::llround(0.01 / dt));
    const long long at_1s = std::llround(1.0 / dt);
    const auto fdt = static_cast<float>(dt);
    double seconds = 0.0, touching_sum = 0.0, pairs_sum = 0.0, points_sum = 0.0;
    long long samples = 0;
    // b2Profile summed over the steps [ms]: collide (narrow phase), solver set-up, velocity
    // iterations, position iterations, broad phase, continuous collision (TOI).
    std::array<double, 6> split{};
    std::pair<double, double> state_1s{0.0, 0.0};
    for (long long done = 0; done < steps;) {
      const long long n = std::min(chunk, steps - done);
      const auto t0 = std::chrono::steady_clock::now();
      for (long long k = 0; k < n; ++k) {
        peer.world.Step(fdt, velocity_iterations, position_iterations);
        const b2Profile& p = peer.world.GetProfile();  // [ms]
        split[0] += p.collide;
        split[1] += p.solveInit;
        split[2] += p.solveVelocity;
        split[3] += p.solvePosition;
        split[4] += p.broadphase;
        split[5] += p.solveTOI;
      }
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      done += n;
      const Contacts c = count_contacts(peer.world);
      touching_sum += c.touching;
      pairs_sum += c.body_pairs;
      points_sum += c.points;
      ++samples;
      if (done <= at_1s) state_1s = motion(peer);
    }
    const auto state_end = motion(peer);
    const Contacts last = count_contacts(peer.world);
    const double ns_step = 1e9 * seconds / static_cast<double>(steps);
    const double touching = touching_sum / static_cast<double>(samples);
    const double pairs = pairs_sum / static_cast<double>(samples);
    const double points = points_sum / static_cast<double>(samples);
    const auto verdict = [&](double d) { return d < stand ? "stands" : "moved"; };

    std::printf("deck %s (voussoir's rigid step %.4g s)\n", deck.c_str(), info.dt);
    std::printf("bodies %d (%zu free), fixtures %d, blocks split into convex pieces %d\n",
                peer.bodies, peer.free_bodies.size(), peer.fixtures, peer.split_blocks);
    std::printf(
        "dt %.6g s, %d velocity / %d position iterations, %lld steps, sleep %s, "
        "shrink %.4g m, lambda %.6g\n",
        dt, velocity_iterations, position_iterations, steps, sleep ? "on" : "off", shrink_by,
        lambda);
    std::printf(
        "touching contacts %.1f (body pairs %.1f, manifold points %.1f; at the end "
        "%d / %d / %d)\n",
        touching, pairs, points, last.touching, last.body_pairs, last.points);
    std::printf(
        "%.0f ns per step, %.1f ns per touching contact per step, %.1f per touching "
        "body pair; %.3g s of wall per simulated second\n",
        ns_step, ns_step / touching, ns_step / pairs, seconds / end);
    const double ms_to_ns = 1e6 / static_cast<double>(steps);
    std::printf(
        "Box2D's profile [ns per step]: collide %.0f, solver set-up %.0f, velocity "
        "iterations %.0f, position iterations %.0f, broad phase %.0f, TOI %.0f\n",
        split[0] * ms_to_ns, split[1] * ms_to_ns, split[2] * ms_to_ns, split[3] * ms_to_ns,
        split[4] * ms_to_ns, split[5] * ms_to_ns);
    std::printf("after 1 s: max displacement %.4g m, max speed %.3g m/s: %s\n", state_1s.first,
                state_1s.second, verdict(state_1s.first));
    std::printf("after %g s: max displacement %.4g m, max speed %.3g m/s: %s\n", end,
                state_end.first, state_end.second, verdict(state_end.first));

    if (!json_path.empty()) {
      const nlohmann::json j = {{"deck", deck},
                                {"voussoir_dt", info.dt},
                                {"bodies", peer.bodies},
                                {"free_bodies", peer.free_bodies.size()},
                                {"fixtures", peer.fixtures},
                                {"split_blocks", peer.split_blocks},
                                {"dt", dt},
                                {"velocity_iterations", velocity_iterations},
                                {"position_iterations", position_iterations},
                                {"steps", steps},
                                {"sleep", sleep},
                                {"shrink", shrink_by},
                                {"lambda", lambda},
                                {"touching_contacts", touching},
                                {"touching_body_pairs", pairs},
                                {"manifold_points", points},
                                {"ns_per_step", ns_step},
                                {"ns_per_contact_step", ns_step / touching},
                                {"ns_per_pair_step", ns_step / pairs},
                                {"wall_s", seconds},
                                {"profile_ns_per_step",
                                 {{"collide", split[0] * ms_to_ns},
                                  {"solve_init", split[1] * ms_to_ns},
                                  {"solve_velocity", split[2] * ms_to_ns},
                                  {"solve_position", split[3] * ms_to_ns},
                                  {"broad_phase", split[4] * ms_to_ns},
                                  {"solve_toi", split[5] * ms_to_ns}}},
                                {"wall_per_simulated_s", seconds / end},
                                {"max_displacement_1s", state_1s.first},
                                {"max_speed_1s", state_1s.second},
                                {"max_displacement_end", state_end.first},
                                {"max_speed_end", state_end.second},
                                {"end", end},
                                {"stand_threshold", stand}};
      std::ofstream(json_path) << j.dump(2) << "\n";
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "peer_box2d: %s\n", e.what());
    return 1;
  }
  return 0;
}
