#pragma once
// The validated contents of a deck (the keys: docs/reference/deck.md). io/deck.cpp fills it from
// TOML and `--set` overrides, one row of its key table per field; everything downstream reads
// only this struct, never the TOML. The initialisers below are the defaults of a deck that omits
// the key (the key table prints them from a default-constructed Config).
// The ground header of the project (core/ includes nothing from another project folder): the
// deck schema and the error types every layer may throw or catch.

#include <array>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace voussoir {

// A bad deck or bad arguments: exit status 2 (the message names the key, the value and what
// is allowed). Thrown by io/ (the deck reader) and by the set-up that checks deck values.
struct DeckError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A number as the error messages of command-line options quote it: printf's %g ("0.1", "-1",
// "1e-30").
inline std::string option_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// A failure during a run (non-finite state, energy blow-up, a limit): exit status 1.
struct RunError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct ModelConfig {
  std::string kind;                    // required: circular_arch, basket_arch, buttressed_arch,
                                       // church, block, polygons
  double radius = 1.0;                 // centreline radius Rc [m]
  double thickness = 0.2;              // arch thickness t [m]
  double embrace = 180.0;              // beta [deg]
  int voussoirs = 11;
  double offset = 0.5;                 // basket d [m]
  double small_radius = 0.5;           // basket r [m]
  std::string shape = "circular";      // buttressed_arch: "circular" or "basket"
  double buttress_width = 0.8;         // B [m]
  double base_depth = 3.0;             // H1 [m]
  double courses = 0.0;                // 0 = monolithic, else course height [m]
  std::vector<double> spans = {4.0, 6.0, 4.0};  // church clear spans [m]
  double height = 5.0;                 // church support height; block height [m]
  double pier_width = 1.0;             // [m]
  double outer_width = 1.2;            // [m]
  double eccentricity = 0.25;          // -
  double voussoir_angle = 2.0;         // [deg]
  double width = 0.5;                  // block width [m]
  double incline = 0.0;                // block ground incline [deg]
  int stack = 1;                       // number of stacked blocks
  std::string file;                    // polygons: path (resolved against the deck folder)
  std::vector<int> fixed;              // polygons: indices of fixed blocks
  double out_of_plane = 1.0;           // [m]
  // Which keys the deck actually gave (so generators can tell a default from a choice).
  std::vector<std::string> given;
  bool has(const std::string& key) const;
};

struct MeshConfig {
  double size = 0.0;                   // target element size [m]; 0 = use through_thickness
  int through_thickness = 1;           // elements across the thickness (arches)
  // Rigid blocks (mesh/minimal.hpp): an outline point goes when the chord replacing it stays
  // within this fraction of the block's thickness of the outline.
  double chord_tolerance = 0.01;
  // The most triangles a model may have: a scene whose estimate is above it is refused before
  // it is meshed, a block whose mesh grows past it while being meshed, and a finished mesh
  // above it (mesh/scene.cpp). 4e6 triangles take about 1.6 GB (390 B each, docs/performance.md)
  // and half a minute of meshing.
  int max_triangles = 4000000;
};

struct MaterialConfig {
  double density = 2000.0;             // kg/m3
  double young = 40e9;                 // Pa
  double poisson = 0.2;
  std::string plane = "strain";        // "strain" or "stress"
  std::string model = "elastic";       // "elastic" (CST blocks) or "rigid" (core/rigid.hpp)
};

struct ContactConfig {
  double friction = 0.6;               // Coulomb mu
  double penalty_factor = 100.0;       // Ep = factor x Lamé's first constant
  double penalty = 0.0;                // Ep [Pa]; 0 = use penalty_factor
  double buffer = 0.0;                 // NBS buffer [m]; 0 = automatic
  // Joint stiffness [N/m3] (contact/joint_stiffness.hpp); 0 = not given: the penalty for
  // elastic blocks, kn = 100 E / L for rigid ones (L: the joint's length); shear 0 = 1/4 of
  // the normal stiffness.
  double normal_stiffness = 0.0;
  double shear_stiffness = 0.0;
  double restitution = 1.0;            // impact restitution in [0, 1]; 1 = no impact damping
  std::vector<std::string> given;      // which [contact] keys the deck gave
  bool has(const std::string& key) const;
};

struct SolverConfig {
  double dt = 0.0;                     // [s]; 0 = "auto"
  // Fraction of the stable limit used by "auto". The limit is a rigorous upper bound on the
  // highest frequency (elements and contact, engine/step.cpp), itself 1.5 to 1.9 x above the
  // true one for contact; docs/error_vs_time.md shows lambda* unchanged from 0.25 to 0.9.
  double dt_safety = 0.9;
  double damping_factor = 1.0;         // scales eta = 2 h sqrt(E rho)
  double end_time = 1.0;               // [s]
  // "explicit" (central difference, every kind of block) or "nscd" (rigid blocks by
  // non-smooth contact dynamics, contact/nscd.hpp; docs/nscd.md)
  std::string scheme = "explicit";
  // nscd: Moreau-Jean's theta in [0.5, 1]; the Gauss-Seidel's relative tolerance on the
  // impulses and its iteration cap per step
  double theta = 0.5;
  double tolerance = 1e-6;
  int max_iterations = 1000;
};

struct BaseConfig {
  std::string signal = "none";         // none, windowed_sine, sine_pulse, file
  double amplitude = 0.0;              // [g]
  double frequency = 1.0;              // [Hz]
  int cycles = 3;
  std::string file;                    // accelerogram (time, acceleration)
  std::string units = "g";             // of the file's acceleration column: "g" or "m/s2"
  std::array<double, 2> band = {0.0, 0.0};  // band-pass [Hz]; {0,0} = no filter
  // baseline correction of the file record before the band-pass (seismic/accelerogram.hpp):
  // "none", or the degree of the polynomial removed from the acceleration: "constant",
  // "linear", "quadratic"
  std::string baseline = "none";
};

struct LoadConfig {
  double gravity = 9.81;               // [m/s2]
  double lambda = 0.0;                 // horizontal body load factor (x gravity)
  // [s] `run`: gravity and lambda g brought on together, linearly, over this time (0: from
  // t = 0). The other commands ramp gravity by their settle's own ramp time.
  double gravity_ramp = 0.0;
  BaseConfig base;
};

struct CapacityConfig {
  double lambda_min = 0.0;             // bracket; both 0 = automatic
  double lambda_max = 0.0;
  double tolerance = 0.005;            // relative bracket width
  // Cundall's local damping coefficient of the quasi-static settle and trials of `capacity`
  // and `sweep` (docs/capacity.md "Quasi-static decisions"; `--dynamic`: none), in [0, 1)
  double local_damping = 0.8;
  // "outgoing": only while the force opposes the motion (a mechanism is not slowed down);
  // "full": Cundall's rule on every step (core/integrate.hpp LocalDamping)
  std::string local_damping_mode = "outgoing";
  // Kinetic damping of the same phases (core/integrate.hpp KineticDamping): every velocity is
  // set to zero once the kinetic energy has fallen this fraction below its peak; in [0, 1),
  // 0 = off (docs/capacity.md "Kinetic damping")
  double kinetic_damping = 1e-3;
  // Mass scaling of the same phases, rigid blocks (engine/step.hpp equalize_rigid_inertia):
  // "equalize" lowers the inertia of the blocks slower than the model's step allows, "none"
  // keeps the true inertia (docs/capacity.md "Mass scaling of the slow blocks")
  std::string mass_scaling = "equalize";
};

// [supports]: prescribed movements of fixed blocks (docs/supports.md; core/supports.hpp).
struct SupportMoveConfig {
  int block = 0;          // index of a fixed block (as `check --mesh-out` numbers them)
  double dx = 0.0;        // displacement of the block [m]
  double dy = 0.0;        // [m]
  double rotation = 0.0;  // counter-clockwise about the block's centroid [deg]
  std::string where;      // where the deck gives `block` ("deck.toml:7:11: "; "" when unknown)
};

struct SupportsConfig {
  std::vector<SupportMoveConfig> moves;  // empty: the supports stay where they are
  double ramp = 0.5;  // [s] over which the moves are reached after the settle under gravity
};

struct OutputConfig {
  std::string file;                    // HDF5 path; empty = no HDF5 output
  double every = 0.01;                 // snapshot interval [s]
  std::vector<std::string> fields = {"position", "velocity", "stress"};
};

struct Config {
  std::string deck_path;               // as given on the command line
  std::string deck_dir;                // folder of the deck, for relative paths
  ModelConfig model;
  MeshConfig mesh;
  MaterialConfig material;
  ContactConfig contact;
  SolverConfig solver;
  LoadConfig load;
  CapacityConfig capacity;
  SupportsConfig supports;
  OutputConfig output;
};

// What the scene generators (mesh/) read of a deck: its [model], [mesh] and [material]
// sections and where the deck is (named in messages; relative model.file is resolved against
// deck_dir). mesh/ takes this, never the whole Config.
struct SceneParams {
  std::string deck_path;
  std::string deck_dir;
  ModelConfig model;
  MeshConfig mesh;
  MaterialConfig material;
};

inline SceneParams scene_params(const Config& c) {
  return {c.deck_path, c.deck_dir, c.model, c.mesh, c.material};
}

// The deck key of a Config field, spelled from the field's path: VOUSSOIR_KEY(model.radius) is
// the text model.radius, and a path that is no field of Config does not compile. The key table
// of io/deck.cpp names every key by its field's path (test DeckKeys), so the scene generators'
// messages (mesh/) take a key's name from here rather than spell it again.
#define VOUSSOIR_KEY(path) \
  (static_cast<void>(sizeof(std::declval<const ::voussoir::Config&>().path)), #path)

}  // namespace voussoir
