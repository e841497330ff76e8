// Checkpoint files (layout and contract in engine/checkpoint.hpp).

#include "engine/checkpoint.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "core/fnv.hpp"
#include "io/deck.hpp"
#include "io/json.hpp"

namespace voussoir {

namespace {

constexpr char kMagic[] = "VOUSSOIR-CKPT\n";  // 14 characters, no terminator written
constexpr std::size_t kMagicSize = sizeof(kMagic) - 1;
// Version 2 adds the impact damping's dissipation to the ledger and the rigid bodies' state
// (empty arrays for elastic blocks); version 3 writes the bodies' centroid displacements
// instead of their centroids, and the outline contact's state for rigid blocks. Version 1 and
// 2 files of elastic runs are still read; rigid ones of version 2 are refused.
constexpr std::uint32_t kVersion = 3;
constexpr std::uint32_t kByteOrderTag = 0x01020304u;
// Contact kind byte: 1 = ContactSystem::save_state bytes follow. (0 was written by builds
// without that interface, frictionless runs only; such files are refused.)
constexpr std::uint8_t kContactBytes = 1;

// Serialisation into a byte string.
struct Out : ByteWriter<Out> {
  std::string buf;
  void bytes(const void* p, std::size_t n) { buf.append(static_cast<const char*>(p), n); }
};

// Bounds-checked reading from the file contents; every failure names the file.
struct In {
  const std::string& buf;
  const std::string& path;
  std::size_t pos = 0;

  [[noreturn]] void fail(const std::string& why) const {
    throw DeckError("restart file '" + path + "': " + why);
  }
  void bytes(void* p, std::size_t n) {
    if (n > buf.size() - pos) fail("truncated (not a complete checkpoint)");
    std::memcpy(p, buf.data() + pos, n);
    pos += n;
  }
  template <class T>
  T value() {
    T v{};
    bytes(&v, sizeof v);
    return v;
  }
  template <class T>
  std::vector<T> array() {
    const auto n = value<std::uint64_t>();
    if (n > (buf.size() - pos) / sizeof(T)) fail("truncated (not a complete checkpoint)");
    std::vector<T> v(n);
    if (n > 0) bytes(v.data(), n * sizeof(T));
    return v;
  }
};

// Writes `data` to `path` atomically: PATH.tmp, fsync, rename.
void write_file_atomically(const std::string& path, const std::string& data) {
  const std::string tmp = path + ".tmp";
  auto fail = [&](const std::string& what) {
    throw OutputError("cannot write checkpoint '" + path + "': " + what + ": " +
                      std::strerror(errno));
  };
  std::error_code ec;
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail("open " + tmp);
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      ::close(fd);
      fail("write " + tmp);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    ::close(fd);
    fail("fsync " + tmp);
  }
  if (::close(fd) != 0) fail("close " + tmp);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) fail("rename " + tmp);
}

}  // namespace

std::uint64_t simulation_fingerprint(const Simulation& sim, double friction) {
  const Model& m = sim.model;
  Fnv f;
  f.array(m.nodes.x0);
  f.array(m.nodes.y0);
  f.array(m.nodes.mass);
  f.array(m.nodes.inv_mass);
  f.array(m.nodes.block);
  f.array(m.tris.n0);
  f.array(m.tris.n1);
  f.array(m.tris.n2);
  f.array(m.tris.block);
  f.value(m.material.density);
  f.value(m.material.young);
  f.value(m.material.poisson);
  f.value(m.material.plane_stress);
  f.value(m.out_of_plane);
  const StepContext& c = sim.ctx;
  for (const double v : {c.dt, c.body_ax, c.body_ay, c.lame_lambda, c.shear_modulus, c.eta})
    f.value(v);
  f.value(c.contact_on);
  f.value(sim.contact.penalty());
  f.value(sim.contact.buffer());
  f.value(friction);
  // Rigid blocks and joint stiffness: the bodies' mass and inertia, the joints' stiffness and
  // restitution. Models without them hash without these fields.
  if (m.is_rigid()) {
    f.array(m.rigid.mass);
    f.array(m.rigid.inertia);
  }
  const ContactParams& p = sim.contact.params();
  if (p.normal_stiffness > 0.0 || p.joint_young > 0.0 || p.shear_stiffness > 0.0 ||
      p.restitution < 1.0)
    for (const double v : {p.normal_stiffness, p.joint_young, p.shear_stiffness, p.restitution})
      f.value(v);
  // Non-smooth contact dynamics: the scheme and its settings (explicit models hash without).
  if (sim.scheme == StepScheme::RigidNscd) {
    f.text("nscd");
    const NscdSettings& n = c.nscd_settings;
    for (const double v : {n.theta, n.tolerance, double(n.max_iterations), n.restitution})
      f.value(v);
  }
  return f.h;
}

void write_checkpoint(const std::string& path, const Simulation& sim, std::uint64_t fingerprint,
                      double friction, const std::vector<double>& driver_state) {
  Out o;
  o.bytes(kMagic, kMagicSize);
  o.value(kVersion);
  o.value(kByteOrderTag);
  o.value(fingerprint);
  o.value<std::int64_t>(sim.step);
  const StepContext& c = sim.ctx;
  for (const double v : {c.time, c.dt, c.prev_body_ax, c.prev_body_ay}) o.value(v);
  const EnergyLedger& l = sim.ledger;
  for (const double v : {l.kinetic, l.strain, l.contact, l.external_work, l.damping_dissipated,
                         l.friction_dissipated, l.impact_dissipated, l.max_energy})
    o.value(v);
  const Nodes& n = sim.model.nodes;
  o.array(n.x);
  o.array(n.y);
  o.array(n.vx);
  o.array(n.vy);
  o.array(sim.viscous_piola);
  const RigidBodies& r = sim.model.rigid;
  for (const auto* v : {&r.ux, &r.uy, &r.theta, &r.vx, &r.vy, &r.omega}) o.array(*v);
  o.value<std::uint8_t>(kContactBytes);
  o.array(sim.contact.save_state());
  if (sim.scheme == StepScheme::RigidNscd) {  // the solver's record of the run so far (models of
                                              // that scheme only)
    o.array(sim.nscd_stats.numbers());
  }
  o.array(driver_state);
  Fnv sum;
  sum.bytes(o.buf.data(), o.buf.size());
  o.value(sum.h);
  write_file_atomically(path, o.buf);
}

std::vector<double> read_checkpoint(const std::string& path, Simulation& sim,
                                    std::uint64_t fingerprint) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw DeckError("restart file '" + path + "': no such file");
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  if (!file) throw DeckError("restart file '" + path + "': cannot read it");
  const std::string buf = text.str();
  In in{buf, path};

  if (buf.size() < kMagicSize + sizeof(std::uint64_t) ||
      buf.compare(0, kMagicSize, kMagic, kMagicSize) != 0)
    in.fail("not a voussoir checkpoint");
  Fnv sum;
  sum.bytes(buf.data(), buf.size() - sizeof(std::uint64_t));
  std::uint64_t stored_sum = 0;
  std::memcpy(&stored_sum, buf.data() + buf.size() - sizeof stored_sum, sizeof stored_sum);
  if (stored_sum != sum.h) in.fail("checksum mismatch (truncated or corrupt)");
  in.pos = kMagicSize;
  const auto version = in.value<std::uint32_t>();
  if (version != kVersion && version != 1 && version != 2)
    in.fail("format version " + std::to_string(version) + ", this program reads versions 1 to " +
            std::to_string(kVersion));
  if (in.value<std::uint32_t>() != kByteOrderTag)
    in.fail("written on a machine of another byte order");
  if (in.value<std::uint64_t>() != fingerprint)
    in.fail(
        "written for another model (the deck or a --set that shapes the model, material, "
        "contact, loads or time step differs)");

  const auto step = in.value<std::int64_t>();
  const double time = in.value<double>();
  const double dt = in.value<double>();
  const double prev_ax = in.value<double>();
  const double prev_ay = in.value<double>();
  if (dt != sim.ctx.dt) in.fail("written with another time step");
  EnergyLedger l;
  for (double* v : {&l.kinetic, &l.strain, &l.contact, &l.external_work, &l.damping_dissipated,
                    &l.friction_dissipated})
    *v = in.value<double>();
  if (version >= 2) l.impact_dissipated = in.value<double>();
  l.max_energy = in.value<double>();
  std::vector<double> x = in.array<double>(), y = in.array<double>();
  std::vector<double> vx = in.array<double>(), vy = in.array<double>();
  std::vector<double> piola = in.array<double>();
  std::vector<std::vector<double>> rigid(6);
  if (version >= 2)
    for (auto& v : rigid) v = in.array<double>();
  const auto contact_kind = in.value<std::uint8_t>();
  const std::vector<char> contact = in.array<char>();
  NscdStats nscd_stats;
  if (sim.scheme == StepScheme::RigidNscd) {
    try {
      nscd_stats = NscdStats::from_numbers(in.array<double>());
    } catch (const std::invalid_argument& e) {
      in.fail(e.what());
    }
  }
  std::vector<double> driver = in.array<double>();
  if (in.pos + sizeof(std::uint64_t) != buf.size()) in.fail("unexpected data after the state");
  const std::size_t nodes = sim.model.nodes.x.size();
  if (step < 0 || x.size() != nodes || y.size() != nodes || vx.size() != nodes ||
      vy.size() != nodes)
    in.fail("node count differs from the model");
  if (!piola.empty() && piola.size() != 4 * std::size_t(sim.model.tris.size()))
    in.fail("triangle count differs from the model");
  if (contact_kind != kContactBytes)
    in.fail("contact state written by a build with another contact interface");

  sim.step = step;
  sim.ctx.time = time;
  sim.ctx.prev_body_ax = prev_ax;
  sim.ctx.prev_body_ay = prev_ay;
  sim.ledger = l;
  Nodes& n = sim.model.nodes;
  n.x = std::move(x);
  n.y = std::move(y);
  n.vx = std::move(vx);
  n.vy = std::move(vy);
  sim.viscous_piola = std::move(piola);
  RigidBodies& r = sim.model.rigid;
  const std::size_t bodies = r.cx.size();
  for (const auto& v : rigid)
    if (v.size() != bodies)
      in.fail(bodies == 0 ? "written for rigid blocks, this model's are elastic"
                          : "rigid body count differs from the model");
  if (bodies > 0) {
    if (version < 3) in.fail("written for rigid blocks by a build before their outline contact");
    r.ux = rigid[0], r.uy = rigid[1], r.theta = rigid[2];
    r.vx = rigid[3], r.vy = rigid[4], r.omega = rigid[5];
    for (std::size_t b = 0; b < bodies; ++b)
      r.cx[b] = r.cx0[b] + r.ux[b], r.cy[b] = r.cy0[b] + r.uy[b];
  }
  if (sim.scheme == StepScheme::RigidNscd) sim.nscd_stats = nscd_stats;
  try {
    sim.contact.restore_state(sim.model, contact);
  } catch (const std::exception& e) {
    in.fail(e.what());
  }
  return driver;
}

}  // namespace voussoir
