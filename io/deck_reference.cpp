// The deck reference (see io/deck_reference.hpp for where each column comes from).
//
// Adding a deck key: give it its reader in io/deck.cpp, a line of meaning in kMeanings below
// and its default in default_of(); then `build/voussoir keys > docs/reference/deck.md`. The test
// DeckReference.EveryKeyHasAMeaning names a key that lacks its line, and
// DeckReference.DocsMatchTheCode a docs/reference/deck.md that was not regenerated.

#include "io/deck_reference.hpp"

#include <algorithm>
#include <charconv>
#include <map>
#include <sstream>

#include "core/scene_kinds.hpp"
#include "core/schema.hpp"
#include "io/deck.hpp"

namespace voussoir {

namespace {

// One line of meaning per key.
const std::map<std::string, std::string>& meanings() {
  static const std::map<std::string, std::string> m = {
      // [model]
      {"model.kind", "scene: which structure the deck builds (SPEC.md section 3)"},
      {"model.radius", "arches: centreline radius Rc (basket: of the reference circle)"},
      {"model.thickness",
       "arches and church: ring thickness t normal to the centreline (church default 0.5)"},
      {"model.embrace", "arches: embrace angle beta of the arch"},
      {"model.voussoirs", "arches: number of voussoirs (blocks of equal centreline length)"},
      {"model.offset", "basket arch: offset d of the large arc's centre below O"},
      {"model.small_radius", "basket arch: radius r of the two small arcs"},
      {"model.shape", "buttressed arch: shape of the arch between the buttresses"},
      {"model.buttress_width", "buttressed arch: buttress width B"},
      {"model.base_depth", "buttressed arch: depth H1 of the ground line below the centre O"},
      {"model.courses",
       "buttressed arch and church: course height of the supports (0 = monolithic)"},
      {"model.spans", "church: clear spans of the three arches, left to right"},
      {"model.height", "church: support height; block: block height (block default 1.0)"},
      {"model.pier_width", "church: width of the two inner piers"},
      {"model.outer_width", "church: width of the two outer buttresses"},
      {"model.eccentricity",
       "church: centre offset c of each pointed half-arch, as a fraction of half the span"},
      {"model.voussoir_angle", "church: angle of the polar voussoirs about their centre"},
      {"model.width", "block: block width"},
      {"model.incline", "block: incline of the fixed ground"},
      {"model.stack", "block: number of blocks stacked on the ground"},
      {"model.file",
       "polygons: polygon text file or gmsh MSH 4.1 file of the blocks (docs/gmsh.md); a text "
       "file's block must be a simple polygon with no corner sharper than 1 degree and no notch "
       "narrower (refused naming the file's line, the block and the vertex; format: "
       "mesh/scenes_polygons.cpp)"},
      {"model.fixed",
       "polygons: indices of the fixed blocks (file order; gmsh: physical tag order); other "
       "kinds: blocks fixed besides the scene's supports (a pier to settle with [supports]); "
       "at least one block must stay free"},
      {"model.out_of_plane", "out-of-plane thickness: masses and forces scale with it"},
      // [mesh]
      {"mesh.chord_tolerance",
       "rigid blocks: an outline point is dropped when its chord stays within this fraction of "
       "the block's thickness"},
      {"mesh.max_triangles",
       "the most triangles a model may have; a deck whose mesh would exceed it is refused "
       "(exit 2) before or while it is meshed"},
      {"mesh.size", "target element size (0: from mesh.through_thickness)"},
      {"mesh.through_thickness", "elements across the arch thickness (or the smallest block)"},
      // [material]
      {"material.density", "mass density rho of the blocks"},
      {"material.young", "Young's modulus E of the blocks"},
      {"material.poisson", "Poisson's ratio nu of the blocks"},
      {"material.plane", "plane strain or plane stress"},
      {"material.model",
       "elastic: constant-strain triangles; rigid: one rigid body per block (docs/rigid.md)"},
      // [contact]
      {"contact.friction", "Coulomb friction coefficient mu of the joints"},
      {"contact.penalty_factor", "contact penalty Ep as a multiple of Lame's first constant"},
      {"contact.penalty", "contact penalty Ep as a value (0: from contact.penalty_factor)"},
      {"contact.buffer", "NBS contact search buffer (0: automatic)"},
      {"contact.normal_stiffness",
       "joint normal stiffness kn, replaces the penalty (not given: penalty, or 100 E / L for "
       "rigid blocks, L the joint's length)"},
      {"contact.shear_stiffness", "joint shear stiffness ks (not given: kn / 4)"},
      {"contact.restitution",
       "impact restitution of rigid blocks (1: no impact damping; below 1 needs "
       "material.model = \"rigid\"; not given: 0.5 for rigid blocks in run, pulse, stability and "
       "capacity --dynamic, none in the quasi-static capacity trials; nscd: 0, plastic impacts)"},
      // [solver]
      {"solver.dt",
       "time step: \"auto\" (explicit: stable limit x solver.dt_safety; nscd: 1e-3 s, or a "
       "record's sampling interval if shorter) or a value"},
      {"solver.dt_safety", "fraction of the stable time step that \"auto\" uses"},
      {"solver.damping_factor", "scales the element viscosity eta = 2 h sqrt(E rho)"},
      {"solver.end_time", "simulated time of `run`"},
      {"solver.scheme",
       "time scheme: explicit central difference, or nscd: rigid blocks by non-smooth contact "
       "dynamics, rigid joints (needs material.model = \"rigid\"; docs/nscd.md)"},
      {"solver.theta", "nscd: Moreau-Jean's theta (0.5: no numerical dissipation)"},
      {"solver.tolerance",
       "nscd: the Gauss-Seidel stops when a sweep changes no body's velocity by more than this "
       "times h |a| or the fastest approach (docs/nscd.md)"},
      {"solver.max_iterations",
       "nscd: most Gauss-Seidel sweeps a step (a step that reaches it is counted unconverged)"},
      // [load]
      {"load.gravity",
       "gravity g, downward (0: a weightless deck, which only `check` and `run` take)"},
      {"load.lambda", "horizontal body load factor of `run` (x gravity)"},
      {"load.gravity_ramp",
       "`run`: gravity and lambda g brought on together, linearly, over this time (0: from "
       "t = 0; a structure loaded over a time long against its slowest mode starts its history "
       "at rest: docs/rigid.md)"},
      {"load.base.signal", "base acceleration history of `pulse` (`run` does not apply it)"},
      {"load.base.amplitude", "peak base acceleration A"},
      {"load.base.frequency", "pulse frequency f"},
      {"load.base.cycles", "windowed sine: number of cycles"},
      {"load.base.file",
       "signal = \"file\": two-column accelerogram (time, acceleration) or PEER NGA .AT2 "
       "record (docs/records.md)"},
      {"load.base.units", "units of the accelerogram's acceleration column"},
      {"load.base.baseline",
       "baseline correction of the accelerogram before the band-pass: the degree of the "
       "polynomial removed from the acceleration, fitted to the displacement (docs/records.md)"},
      {"load.base.band", "band-pass filter of the accelerogram [low, high] ([0, 0]: none)"},
      // [capacity]
      {"capacity.lambda_min",
       "lower end of the starting bracket of `capacity` (stable); above 0, checked by a trial "
       "beside lambda_max's (a collapse there widens the bracket down)"},
      {"capacity.lambda_max",
       "upper end of the starting bracket (both 0: from limit analysis); checked by a trial"},
      {"capacity.tolerance", "relative width of the final bracket: (hi - lo) / hi"},
      {"capacity.local_damping",
       "coefficient of the local damping of the quasi-static settle and trials of `capacity` "
       "and `sweep` (0: none; `--dynamic`: off; docs/capacity.md)"},
      {"capacity.local_damping_mode",
       "outgoing: damp only while the force opposes the motion (a mechanism is not slowed); "
       "full: Cundall's rule at every step"},
      {"capacity.kinetic_damping",
       "kinetic damping of the same phases: every velocity set to zero once the kinetic energy "
       "has fallen this fraction below its peak (0: none; `--dynamic`: off; docs/capacity.md)"},
      {"capacity.mass_scaling",
       "rigid blocks in the same phases: equalize lowers the mass and inertia of each block "
       "until its own stable step is the model's (loads keep the true masses); none: true "
       "inertia (`--dynamic`: none; docs/capacity.md)"},
      // [supports]
      {"supports.moves",
       "prescribed movements of fixed blocks: block (its number in `check`, which lists the "
       "supports), dx, dy [m] and rotation [deg, counter-clockwise about its centroid]; every "
       "command settles under gravity, moves them over `ramp`, then runs on the moved "
       "structure (`run`: from t = 0; docs/supports.md)"},
      {"supports.ramp",
       "time over which the moves are reached, by a ramp with zero velocity and acceleration "
       "at both ends (docs/supports.md)"},
      // [output]
      {"output.file", "HDF5 file of `run` / `pulse` (XDMF beside it); empty: none"},
      {"output.every", "snapshot interval"},
      {"output.fields",
       "snapshot fields: position (with displacement), velocity, stress (elastic blocks)"},
  };
  return m;
}

std::string number(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

std::string quoted(const std::string& s) {
  return "\"" + s + "\"";
}

template <typename T, typename F>
std::string list(const T& items, F show) {
  std::string s = "[";
  for (std::size_t k = 0; k < items.size(); ++k) s += (k ? ", " : "") + show(items[k]);
  return s + "]";
}

// The default of `key` in a deck that omits it, from a default-constructed Config.
std::string default_of(const std::string& key) {
  static const Config c;
  const ModelConfig& m = c.model;
  static const std::map<std::string, std::string> d = {
      {"model.kind", "required"},
      {"model.radius", number(m.radius)},
      {"model.thickness", number(m.thickness)},
      {"model.embrace", number(m.embrace)},
      {"model.voussoirs", std::to_string(m.voussoirs)},
      {"model.offset", number(m.offset)},
      {"model.small_radius", number(m.small_radius)},
      {"model.shape", quoted(m.shape)},
      {"model.buttress_width", number(m.buttress_width)},
      {"model.base_depth", number(m.base_depth)},
      {"model.courses", number(m.courses)},
      {"model.spans", list(m.spans, number)},
      {"model.height", number(m.height)},
      {"model.pier_width", number(m.pier_width)},
      {"model.outer_width", number(m.outer_width)},
      {"model.eccentricity", number(m.eccentricity)},
      {"model.voussoir_angle", number(m.voussoir_angle)},
      {"model.width", number(m.width)},
      {"model.incline", number(m.incline)},
      {"model.stack", std::to_string(m.stack)},
      {"model.file", "none"},
      {"model.fixed", list(m.fixed, [](int v) { return std::to_string(v); })},
      {"model.out_of_plane", number(m.out_of_plane)},
      {"mesh.chord_tolerance", number(c.mesh.chord_tolerance)},
      {"mesh.max_triangles", std::to_string(c.mesh.max_triangles)},
      {"mesh.size", number(c.mesh.size)},
      {"mesh.through_thickness", std::to_string(c.mesh.through_thickness)},
      {"material.density", number(c.material.density)},
      {"material.young", number(c.material.young)},
      {"material.poisson", number(c.material.poisson)},
      {"material.plane", quoted(c.material.plane)},
      {"material.model", quoted(c.material.model)},
      {"contact.friction", number(c.contact.friction)},
      {"contact.penalty_factor", number(c.contact.penalty_factor)},
      {"contact.penalty", number(c.contact.penalty)},
      {"contact.buffer", number(c.contact.buffer)},
      {"contact.normal_stiffness", "none"},
      {"contact.shear_stiffness", "none"},
      {"contact.restitution", number(c.contact.restitution)},
      {"solver.dt", c.solver.dt == 0.0 ? quoted("auto") : number(c.solver.dt)},
      {"solver.dt_safety", number(c.solver.dt_safety)},
      {"solver.damping_factor", number(c.solver.damping_factor)},
      {"solver.end_time", number(c.solver.end_time)},
      {"solver.scheme", quoted(c.solver.scheme)},
      {"solver.theta", number(c.solver.theta)},
      {"solver.tolerance", number(c.solver.tolerance)},
      {"solver.max_iterations", std::to_string(c.solver.max_iterations)},
      {"load.gravity", number(c.load.gravity)},
      {"load.lambda", number(c.load.lambda)},
      {"load.gravity_ramp", number(c.load.gravity_ramp)},
      {"load.base.signal", quoted(c.load.base.signal)},
      {"load.base.amplitude", number(c.load.base.amplitude)},
      {"load.base.frequency", number(c.load.base.frequency)},
      {"load.base.cycles", std::to_string(c.load.base.cycles)},
      {"load.base.file", "none"},
      {"load.base.units", quoted(c.load.base.units)},
      {"load.base.baseline", quoted(c.load.base.baseline)},
      {"load.base.band", list(c.load.base.band, number)},
      {"capacity.lambda_min", number(c.capacity.lambda_min)},
      {"capacity.lambda_max", number(c.capacity.lambda_max)},
      {"capacity.tolerance", number(c.capacity.tolerance)},
      {"capacity.local_damping", number(c.capacity.local_damping)},
      {"capacity.local_damping_mode", quoted(c.capacity.local_damping_mode)},
      {"capacity.kinetic_damping", number(c.capacity.kinetic_damping)},
      {"capacity.mass_scaling", quoted(c.capacity.mass_scaling)},
      {"supports.moves", "[] (none)"},
      {"supports.ramp", number(c.supports.ramp)},
      {"output.file", "none"},
      {"output.every", number(c.output.every)},
      {"output.fields", list(c.output.fields, quoted)},
  };
  const auto it = d.find(key);
  std::string out = it == d.end() ? std::string() : it->second;
  // Keys a scene kind cannot do without (core/scene_kinds.hpp).
  for (const SceneKind& k : scene_kinds())
    for (const RequiredKey& r : k.required)
      if (key == r.key) out = "required by kind \"" + std::string(k.name) + "\"";
  return out;
}

std::string cell(std::string s) {
  std::string out;
  for (char ch : s) out += ch == '|' ? std::string("\\|") : std::string(1, ch);
  return out;
}

}  // namespace

std::vector<KeyReference> deck_reference() {
  std::vector<KeyReference> out;
  for (const std::string& key : known_keys()) {
    const KeyRule rule = describe_key(key);
    KeyReference r;
    r.key = key;
    r.type = rule.type;
    r.unit = rule.unit;
    r.allowed = rule.allowed;
    r.default_value = default_of(key);
    const auto it = meanings().find(key);
    if (it != meanings().end()) r.meaning = it->second;
    out.push_back(r);
  }
  return out;
}

std::vector<std::string> stale_reference_keys() {
  std::vector<std::string> out;
  const std::vector<std::string>& known = known_keys();
  for (const auto& [key, meaning] : meanings())
    if (std::find(known.begin(), known.end(), key) == known.end()) out.push_back(key);
  return out;
}

std::string deck_reference_markdown() {
  std::ostringstream md;
  md << "# Deck reference\n\n"
     << "Generated by `voussoir keys` from the deck reader (io/deck.cpp: keys, types, units,\n"
     << "allowed values), the defaults of core/schema.hpp and the meanings in\n"
     << "io/deck_reference.cpp. Do not edit: regenerate with\n"
     << "`build/voussoir keys > docs/reference/deck.md` (the `DeckReference` tests fail when this\n"
     << "file is stale or a key is missing).\n\n"
     << "Decks are TOML; every key can also be given on the command line as\n"
     << "`--set SECTION.KEY=VALUE`. An unknown key, a value of the wrong type or outside the\n"
     << "allowed values is an error (exit status 2) that names the key and the value. Lengths in\n"
     << "m, angles in degrees, accelerations in g where the unit says so. A key the chosen\n"
     << "`model.kind` does not use is accepted and ignored.\n";
  std::string section;
  for (const KeyReference& r : deck_reference()) {
    const std::string sec = r.key.substr(0, r.key.rfind('.'));
    if (sec != section) {
      section = sec;
      md << "\n## [" << sec << "]\n\n"
         << "| key | type | unit | default | allowed | meaning |\n"
         << "|---|---|---|---|---|---|\n";
    }
    md << "| `" << r.key.substr(sec.size() + 1) << "` | " << cell(r.type) << " | "
       << cell(r.unit.empty() ? "-" : r.unit) << " | " << cell(r.default_value) << " | "
       << cell(r.allowed) << " | " << cell(r.meaning) << " |\n";
  }
  return md.str();
}

}  // namespace voussoir
