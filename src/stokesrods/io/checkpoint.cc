#include "stokesrods/io/checkpoint.h"

#include <cstring>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "stokesrods/io/writers.h"

namespace stokesrods {
namespace {

constexpr char kMagic[8] = {'S', 'R', 'C', 'K', 'P', 'T', '\0', '\0'};
// 4: the earlier drags; 5: the bodies' previous poses; 6: the dense 𝕄's reuse history; 7: its
// skipped measurements; 8: the last row of the time series
constexpr std::uint32_t kVersion = 9;
constexpr std::uint32_t kOldestVersion = 2;  // without the controls

std::uint64_t Fnv1a(const char* data, std::size_t bytes, std::uint64_t hash = 14695981039346656037ull) {
  for (std::size_t i = 0; i < bytes; ++i) {
    hash ^= static_cast<unsigned char>(data[i]);
    hash *= 1099511628211ull;
  }
  return hash;
}

class Writer {
 public:
  template <typename T>
  void Put(const T& value) { Raw(&value, sizeof value); }
  void Raw(const void* data, std::size_t bytes) {
    if (bytes > 0) out_.append(static_cast<const char*>(data), bytes);
  }
  void Vector(const VecX& v) {
    Put(static_cast<std::int64_t>(v.size()));
    Raw(v.data(), sizeof(double) * static_cast<std::size_t>(v.size()));
  }
  std::string& text() { return out_; }

 private:
  std::string out_;
};

class Reader {
 public:
  Reader(const std::string& path, const std::string& text) : path_(path), text_(text) {}
  template <typename T>
  T Get() {
    T value;
    Raw(&value, sizeof value);
    return value;
  }
  void Raw(void* data, std::size_t bytes) {
    if (bytes == 0) return;  // an empty vector's data() may be null: no memcpy (UBSan)
    if (bytes > text_.size() - at_) Fail("truncated");
    std::memcpy(data, text_.data() + at_, bytes);
    at_ += bytes;
  }
  /// A vector of `expected` entries, or (allow_empty) none.
  VecX Vector(Eigen::Index expected, const char* what, bool allow_empty = false) {
    const auto n = Get<std::int64_t>();
    if (n != expected && !(allow_empty && n == 0))
      Fail(fmt::format("{} has {} entries, the model needs {}", what, n, expected));
    VecX v(n);
    Raw(v.data(), sizeof(double) * static_cast<std::size_t>(n));
    return v;
  }
  [[noreturn]] void Fail(const std::string& problem) const {
    throw IoError(fmt::format("{}: cannot resume from this checkpoint: {}", path_, problem));
  }
  std::size_t at() const { return at_; }

 private:
  const std::string& path_;
  const std::string& text_;
  std::size_t at_ = 0;
};

// Each rod's rotation rate and point loads (version 3).
std::vector<RodControls> ReadControls(const Model& model, Reader* r) {
  std::vector<RodControls> controls(model.rods.size());
  for (std::size_t i = 0; i < model.rods.size(); ++i) {
    controls[i].omega = r->Get<double>();
    const auto count = r->Get<std::int64_t>();
    if (count < 0)
      r->Fail(fmt::format("rod {} has {} point loads", i + 1, count));
    for (std::int64_t k = 0; k < count; ++k) {
      PointLoad load;
      load.node = static_cast<int>(r->Get<std::int64_t>());
      r->Raw(load.force.data(), 3 * sizeof(double));
      if (load.node < 0 || load.node >= model.rods[i].num_nodes())
        r->Fail(fmt::format("a point load on rod {} at node {}, which it does not have", i + 1,
                            load.node));
      controls[i].loads.push_back(load);
    }
  }
  return controls;
}

}  // namespace

std::uint64_t ModelFingerprint(const Model& model) {
  Writer w;
  w.Put(static_cast<std::int64_t>(model.num_dofs));
  for (const RodModel& rod : model.rods) {
    w.Put(static_cast<std::int64_t>(rod.num_nodes()));
    w.Raw(rod.rest_positions.data(), sizeof(double) * static_cast<std::size_t>(rod.rest_positions.size()));
    w.Vector(rod.mass);
    w.Put(rod.axial_stiffness);
    w.Put(rod.bending_stiffness);
    w.Put(rod.twisting_stiffness);
  }
  for (const BodyModel& body : model.bodies) {  // nothing without bodies (older files still read)
    w.Put(body.radius);
    w.Put(static_cast<std::int64_t>(body.num_points()));
    w.Put(static_cast<std::int64_t>(body.motion));
  }
  return Fnv1a(w.text().data(), w.text().size());
}

void SaveCheckpoint(const std::string& path, const Model& model, const Checkpoint& c) {
  Writer w;
  w.Raw(kMagic, sizeof kMagic);
  w.Put(kVersion);
  w.Put(ModelFingerprint(model));
  w.Put(c.time_step);
  w.Put(c.state.time);
  w.Put(static_cast<std::int64_t>(c.state.step));
  w.Vector(c.state.q);
  w.Vector(c.state.velocity);
  for (const RodFrames& rod : c.state.rods) {
    for (std::size_t j = 0; j < rod.frames.size(); ++j) {
      w.Raw(rod.frames[j].d1.data(), 3 * sizeof(double));
      w.Raw(rod.frames[j].d2.data(), 3 * sizeof(double));
      w.Raw(rod.tangents[j].data(), 3 * sizeof(double));
    }
    w.Vector(rod.reference_twist);
  }
  w.Vector(c.history.previous_q);
  w.Vector(c.history.previous_velocity);
  w.Put(c.history.previous_h);
  w.Vector(c.history.hydro_force);
  w.Put(static_cast<std::int64_t>(c.counters.newton_iterations));
  w.Put(c.counters.max_penetration);
  w.Put(static_cast<std::int64_t>(c.counters.step_reductions));
  for (const BodyPose& pose : c.state.bodies) {  // nothing without bodies (older files still read)
    w.Raw(pose.center.data(), 3 * sizeof(double));
    w.Raw(pose.rotation.data(), 9 * sizeof(double));
  }
  for (const RodModel& rod : model.rods) {
    w.Put(rod.omega);
    w.Put(static_cast<std::int64_t>(rod.loads.size()));
    for (const PointLoad& load : rod.loads) {
      w.Put(static_cast<std::int64_t>(load.node));
      w.Raw(load.force.data(), 3 * sizeof(double));
    }
  }
  for (const VecX& drag : c.history.earlier_drags) w.Vector(drag);
  w.Put(static_cast<std::int64_t>(c.history.previous_poses.size()));  // version 5
  for (const BodyPose& pose : c.history.previous_poses) {
    w.Raw(pose.center.data(), 3 * sizeof(double));
    w.Raw(pose.rotation.data(), 9 * sizeof(double));
  }
  const MobilityReuseHistory& reuse = c.history.mobility_reuse;  // version 6
  w.Put(static_cast<std::int64_t>(reuse.geometries.size()));
  w.Put(static_cast<std::int64_t>(reuse.since));
  w.Put(static_cast<std::int64_t>(reuse.interval));
  for (const VecX& g : reuse.geometries) w.Vector(g);
  w.Put(static_cast<std::int64_t>(reuse.skip));  // version 7
  w.Put(static_cast<std::int64_t>(reuse.skip_length));
  w.Put(static_cast<std::int64_t>(c.last_row.size()));  // version 8
  w.Raw(c.last_row.data(), sizeof(double) * c.last_row.size());
  w.Vector(c.history.older_velocity);  // version 9: the cubic predictor's history
  w.Put(c.history.older_h);
  w.Put(static_cast<std::int64_t>(c.history.cubic_predictor ? 1 : 0));
  w.Put(c.history.damped_miss);
  w.Put(Fnv1a(w.text().data(), w.text().size()));
  WriteFileAtomically(path, w.text());
}

Checkpoint LoadCheckpoint(const std::string& path, const Model& model) {
  const std::optional<std::string> file = ReadFileText(path);
  if (!file) throw IoError(fmt::format("{}: cannot open the checkpoint", path));
  const std::string& text = *file;
  Reader r(path, text);
  char magic[sizeof kMagic];
  if (text.size() < sizeof kMagic || (r.Raw(magic, sizeof magic), std::memcmp(magic, kMagic, sizeof kMagic) != 0))
    r.Fail("not a stokesrods checkpoint");
  const auto version = r.Get<std::uint32_t>();
  if (version < kOldestVersion || version > kVersion)
    r.Fail(fmt::format("format version {}, this stokesrods reads versions {} to {}", version,
                       kOldestVersion, kVersion));
  std::uint64_t stored_sum = 0;
  if (text.size() < sizeof stored_sum + r.at()) r.Fail("truncated");
  std::memcpy(&stored_sum, text.data() + text.size() - sizeof stored_sum, sizeof stored_sum);
  if (stored_sum != Fnv1a(text.data(), text.size() - sizeof stored_sum))
    r.Fail("damaged (its checksum does not match its contents)");
  if (r.Get<std::uint64_t>() != ModelFingerprint(model))
    r.Fail("it belongs to another model (rods, nodes, rest shapes or materials differ)");
  Checkpoint c;
  c.time_step = r.Get<double>();
  c.state.time = r.Get<double>();
  c.state.step = static_cast<long>(r.Get<std::int64_t>());
  c.state.q = r.Vector(model.num_dofs, "q");
  c.state.velocity = r.Vector(model.num_dofs, "the velocity");
  for (const RodModel& rod : model.rods) {
    RodFrames f;
    f.frames.resize(static_cast<std::size_t>(rod.num_nodes() - 1));
    f.tangents.resize(f.frames.size());
    for (std::size_t j = 0; j < f.frames.size(); ++j) {
      r.Raw(f.frames[j].d1.data(), 3 * sizeof(double));
      r.Raw(f.frames[j].d2.data(), 3 * sizeof(double));
      r.Raw(f.tangents[j].data(), 3 * sizeof(double));
    }
    f.reference_twist = r.Vector(rod.num_nodes(), "a reference twist");
    c.state.rods.push_back(std::move(f));
  }
  c.history.previous_q = r.Vector(model.num_dofs, "the previous q", true);
  c.history.previous_velocity = r.Vector(model.num_dofs, "the previous velocity", true);
  c.history.previous_h = r.Get<double>();
  c.history.hydro_force = r.Vector(model.hydro_size(), "the drag", true);
  c.counters.newton_iterations = static_cast<long>(r.Get<std::int64_t>());
  c.counters.max_penetration = r.Get<double>();
  c.counters.step_reductions = static_cast<long>(r.Get<std::int64_t>());
  c.state.bodies.resize(model.bodies.size());
  for (BodyPose& pose : c.state.bodies) {
    if (r.at() + 12 * sizeof(double) + sizeof stored_sum > text.size()) r.Fail("truncated");
    r.Raw(pose.center.data(), 3 * sizeof(double));
    r.Raw(pose.rotation.data(), 9 * sizeof(double));
  }
  if (version >= 3) c.controls = ReadControls(model, &r);
  if (version >= 4)
    for (VecX& drag : c.history.earlier_drags) drag = r.Vector(model.hydro_size(), "an earlier drag", true);
  if (version >= 5) {  // BDF2's previous poses of the bodies: none, or one per body
    const auto count = r.Get<std::int64_t>();
    if (count != 0 && count != static_cast<std::int64_t>(model.bodies.size()))
      r.Fail(fmt::format("{} previous body poses for a model of {} bodies", count, model.bodies.size()));
    c.history.previous_poses.resize(static_cast<std::size_t>(count));
    for (BodyPose& pose : c.history.previous_poses) {
      if (r.at() + 12 * sizeof(double) + sizeof stored_sum > text.size()) r.Fail("truncated");
      r.Raw(pose.center.data(), 3 * sizeof(double));
      r.Raw(pose.rotation.data(), 9 * sizeof(double));
    }
  }
  if (version >= 6) {  // the dense 𝕄's reuse: where its history was assembled, its counters
    MobilityReuseHistory& reuse = c.history.mobility_reuse;
    const auto held = r.Get<std::int64_t>(), since = r.Get<std::int64_t>(),
               interval = r.Get<std::int64_t>();
    if (held < 0 || held > MobilityReuse::kMaxHeld || since < 0 || interval < 1 ||
        interval > MobilityReuse::kMaxInterval || since >= interval)
      r.Fail(fmt::format("a reuse history of {} assemblies, {} of {} updates is not one", held,
                         since, interval));
    reuse.since = static_cast<int>(since);
    reuse.interval = static_cast<int>(interval);
    for (std::int64_t k = 0; k < held; ++k)
      reuse.geometries.push_back(r.Vector(3 * model.num_nodes, "a geometry of the reuse"));
  }
  if (version >= 7) {  // the reuse's measurements skipped
    MobilityReuseHistory& reuse = c.history.mobility_reuse;
    const auto skip = r.Get<std::int64_t>(), length = r.Get<std::int64_t>();
    if (skip < 0 || length < skip || length > MobilityReuse::kMaxSkip)
      r.Fail(fmt::format("the reuse's {} of {} skipped measurements is not possible", skip, length));
    reuse.skip = static_cast<int>(skip);
    reuse.skip_length = static_cast<int>(length);
  }
  if (version >= 8) {  // the last row of the time series
    const auto count = r.Get<std::int64_t>();
    if (count < 0 || static_cast<std::size_t>(count) > (text.size() - r.at()) / sizeof(double))
      r.Fail(fmt::format("a time-series row of {} values", count));
    c.last_row.resize(static_cast<std::size_t>(count));
    r.Raw(c.last_row.data(), sizeof(double) * c.last_row.size());
  }
  if (version >= 9) {  // the cubic predictor's history (sim/integrator.cc, Predict)
    c.history.older_velocity = r.Vector(model.num_dofs, "the velocity before the previous", true);
    c.history.older_h = r.Get<double>();
    const auto cubic = r.Get<std::int64_t>();
    if (cubic != 0 && cubic != 1) r.Fail(fmt::format("a predictor choice of {}", cubic));
    c.history.cubic_predictor = cubic == 1;
    c.history.damped_miss = r.Get<double>();
    if (!(c.history.damped_miss >= 0.0)) r.Fail("a negative or undefined predictor miss");
  }
  if (r.at() + sizeof stored_sum != text.size()) r.Fail("unexpected data after the contents");
  return c;
}

}  // namespace stokesrods
