// The configuration file (SPEC "Configuration"): plain structs with defaults, read strictly.
//
// Each struct lists its fields once, in VisitFields; that one list drives the TOML reader (which
// rejects unknown keys, wrong types and missing required keys), the echo of the resolved
// configuration (show-config, summary.json) and the Python attributes.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "stokesrods/common/types.h"

namespace stokesrods {

/// Bad input: names the file, the key (dotted path) and what is wrong. Exit code 2.
class ConfigError : public std::runtime_error {
 public:
  ConfigError(const std::string& file, const std::string& key, const std::string& problem);
  const std::string& file() const { return file_; }
  const std::string& key() const { return key_; }

 private:
  std::string file_, key_;
};

struct RunConfig {
  std::string name = "stokesrods";
  std::string output;                     ///< default: out/<name>
  std::string mode = "dynamic";           ///< "dynamic" | "static"
  std::optional<double> duration;         ///< [s]
  std::optional<double> t_bar_end;        ///< normalized end time (paper eq. 24b)
  double time_step = 1e-3;                ///< [s]
  std::string integrator = "euler";       ///< "euler" (paper eq. 22) | "bdf2" (second order)
  std::optional<double> output_interval;  ///< [s], default: 1/100 of the run
  bool frames = true;
  std::string frames_format = "ascii";    ///< "ascii" | "binary" (base64) | "appended" (raw)
  std::optional<double> checkpoint_interval;  ///< [s], default: 1/10 of the run
  /// [s] of wall time: if set, a checkpoint is written at the first restart point (every 120 steps
  /// and every checkpoint_interval) after this much wall time since the last one
  std::optional<double> checkpoint_wall_interval;
  /// Stop at the first output row where rod 1 has buckled by analyze's rule (io/analysis.h: its
  /// last node farther than 2R from its clamp's vertical); status "completed". Saves the costly
  /// post-buckling motion (self-contact) in buckling-threshold sweeps.
  bool stop_when_buckled = false;
};

struct FluidConfig {
  std::string model = "rss";       ///< "rss" | "lsbt" | "rft" | "none"
  double viscosity = 1.0;          ///< μ [Pa·s]
  double regularization = 1.02;    ///< ε / r0
  std::string coupling = "implicit";  ///< "implicit" | "explicit"
  /// "auto" (dense up to 500 nodes, else matrix-free) | "dense" | "matrix_free" (RSS only)
  std::string mobility = "auto";
  double far_field_tolerance = 1e-8;  ///< matrix-free: relative error of the far field [–]
  double fast_sum_tolerance = 1e-4;   ///< matrix-free: error bound of the FMM far-field sum [–]
  double mobility_reuse_tolerance = 1e-4;  ///< dense: error of 𝕄 reused across steps [–]
  std::string solver = "krylov";      ///< implicit coupling: "krylov" (GMRES) | "direct" (dense LU)
  double krylov_tolerance = 1e-6;     ///< GMRES relative residual [–]
  bool krylov_rotate_preconditioner = true;  ///< the kept preconditioner follows the rods' rotation
  int krylov_coarse_rebuild_period =
      0;  ///< matrix-free: coarse level rebuilt every k rebuilds; 0: by cost
};

struct ContactConfig {
  bool enabled = true;
  double tolerance = 1e-3;  ///< resolved when every distance ≥ (r_a + r_b)(1 − tolerance)
  int max_rounds = 50;      ///< solve–detect–re-solve rounds per step before a failure
};

struct GravityConfig {
  Vec3 acceleration = Vec3::Zero();  ///< [m/s²]
};

struct SolverConfig {
  double newton_tolerance = 1e-8;   ///< residual force / force scale
  int newton_max_iterations = 30;
  int jacobian_max_age = 1;         ///< steps a factorized banded Newton matrix may be reused
  double damping = 0.0;             ///< isotropic viscous damping per unit length [Pa·s]
  int max_step_halvings = 0;        ///< a failed step is retried as two of h/2, this deep
};

/// The fluid velocity on a plane grid at chosen times (paper Fig. 6b).
struct FlowFieldConfig {
  std::vector<double> times;                   ///< [s]; empty: no flow field
  Vec3 origin = Vec3(-0.02, 0.0, -0.23);       ///< a corner of the plane [m]
  Vec3 u = Vec3(0.07, 0.0, 0.0);               ///< first edge of the plane [m]
  Vec3 v = Vec3(0.0, 0.0, 0.25);               ///< second edge of the plane [m]
  std::vector<int> resolution = {36, 126};     ///< grid points along u and along v
};

struct PointLoadConfig {
  int node = 0;
  Vec3 force = Vec3::Zero();  ///< [N]
};

struct RodConfig {
  std::string shape = "helix";  ///< "helix" | "straight" | "points"
  double radius = 1e-3;         ///< r0 [m]
  double young_modulus = 10e6;  ///< E [Pa]
  double poisson_ratio = 0.5;   ///< ν
  double density = 1000.0;      ///< ρ [kg/m³]
  int nodes = 65;               ///< N (points: taken from `points`)
  double axis_length = 0.2;     ///< l0 [m]
  double pitch = 0.05;          ///< λ [m], helix
  double helix_radius = 0.01;   ///< R [m], helix
  std::string handedness = "right";
  /// helix: "within" (l0 spans the whole rod, node 0 to the last) | "above" (l0 is the helical
  /// part below node 2; the clamped edge and the 45° lead-in sit above it)
  std::string lead_in = "within";
  Vec3 base = Vec3::Zero();     ///< node 0 [m]
  int clamped_nodes = 2;
  std::optional<double> omega;      ///< [rad/s] about +ẑ
  std::optional<double> omega_bar;  ///< ω μ l0⁴ / EI
  std::vector<Vec3> points;         ///< shape = "points"
  std::vector<PointLoadConfig> loads;
  /// The body (from 1) whose frame holds the clamped nodes and against which the motor turns;
  /// 0: none (the clamp is fixed in space).
  int body = 0;
};

/// A rigid cell body (SPEC "Additions"): its surface as regularized Stokeslets (fluid/rigid_body.h).
struct BodyConfig {
  std::string shape = "sphere";            ///< "sphere" | "spheroid"
  double radius = 0.02;                    ///< a [m]; a spheroid's equatorial radius b
  double half_length = 0.0;                ///< a spheroid's polar semi-axis [m]
  Vec3 axis = Vec3::UnitZ();               ///< a spheroid's axis at the start (normalized when read)
  Vec3 center = Vec3::Zero();              ///< [m]
  std::string motion = "fixed";            ///< "free" | "fixed" | "prescribed"
  Vec3 velocity = Vec3::Zero();            ///< [m/s], "prescribed" only
  Vec3 angular_velocity = Vec3::Zero();    ///< [rad/s] about the centre, "prescribed" only
  Vec3 force = Vec3::Zero();               ///< a constant load on the body [N], "free" only
  Vec3 torque = Vec3::Zero();              ///< a constant torque about its centre [N·m], "free" only
  int surface_points = 400;                ///< regularized Stokeslets on the surface
};

/// A plane no-slip wall.
struct WallConfig {
  Vec3 point = Vec3::Zero();               ///< a point of the wall [m]
  Vec3 normal = Vec3::UnitZ();             ///< into the fluid (normalized when read)
};

struct Config {
  std::string file;  ///< where it was read from (for messages)
  RunConfig run;
  FluidConfig fluid;
  ContactConfig contact;
  GravityConfig gravity;
  SolverConfig solver;
  FlowFieldConfig flow_field;
  std::vector<RodConfig> rods;
  std::vector<BodyConfig> bodies;
  std::optional<WallConfig> wall;
};

/// Reads and validates a configuration file; `overrides` are "dotted.key=value" strings applied
/// before validation (SPEC --set: rods.KEY sets it on every rod, rods.K.KEY on rod K, from 1).
/// Throws ConfigError.
Config LoadConfig(const std::string& path, const std::vector<std::string>& overrides = {});

/// The same from TOML text (tests, Python dicts); `file` names it in messages.
Config ParseConfig(const std::string& toml_text, const std::string& file,
                   const std::vector<std::string>& overrides = {});

/// One configuration key: dotted path ("run.time_step", "rods.radius", "rods.loads[].node"),
/// its TOML type and its default as TOML text ("" when unset by default).
struct ConfigKey {
  std::string key, type, default_value;
};
/// Every key in the order of the field lists (the reader's); docs/config_keys.md is made from it.
std::vector<ConfigKey> ListConfigKeys();

/// The resolved configuration (every default filled in) as TOML text / as JSON text.
std::string ConfigToToml(const Config& config);
std::string ConfigToJson(const Config& config);

}  // namespace stokesrods
