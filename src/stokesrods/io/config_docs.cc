// The user guide of every configuration key (docs/config_keys.md): names, types and defaults
// come from the field lists the reader uses (ListConfigKeys); the meanings are here, one per
// key. A key without a meaning, or a meaning without a key, is an error (the docs test fails).
#include "stokesrods/io/config_docs.h"

#include <map>
#include <stdexcept>

#include <fmt/format.h>

#include "stokesrods/io/config.h"

namespace stokesrods {
namespace {

const std::map<std::string, std::string>& Meanings() {
  static const std::map<std::string, std::string> m = {
      {"run.name", "name of the run (messages; the default output directory is out/NAME)"},
      {"run.output",
       "output directory, created if missing (default out/NAME; `--output` overrides it)"},
      {"run.mode",
       "\"dynamic\": time stepping; \"static\": the equilibrium under the loads and boundary "
       "conditions (one row)"},
      {"run.duration",
       "simulated time [s]; a dynamic run gives exactly one of duration and t_bar_end (`--set` of "
       "one replaces the other)"},
      {"run.t_bar_end",
       "end time in units of μ l0⁴/EI of rod 1 (paper eq. 24b), instead of duration"},
      {"run.time_step", "h [s]"},
      {"run.integrator",
       "\"euler\" (implicit Euler, paper eq. 22, first order) or \"bdf2\" (second order; implicit "
       "coupling only)"},
      {"run.output_interval",
       "simulated seconds between rows of timeseries.csv and between frames (default 1/100 of the "
       "run)"},
      {"run.frames", "write ParaView frames (rods.pvd, frames/*.vtp)"},
      {"run.frames_format",
       "\"ascii\" (readable, 10 digits), \"binary\" (inline base64: exact doubles, about the "
       "ASCII's size) or \"appended\" (raw bytes at the end of each file: exact, the smallest and "
       "fastest to read)"},
      {"run.checkpoint_interval",
       "simulated seconds between checkpoints (default 1/10 of the run)"},
      {"run.checkpoint_wall_interval",
       "wall-clock seconds between checkpoints instead (written at the next restart point)"},
      {"run.stop_when_buckled",
       "stop (status completed) at the first output row where rod 1 has buckled by `analyze`'s "
       "rule: its last node farther than 2R from the vertical through its clamp (rod 1 a helix; "
       "dynamic runs)"},
      {"fluid.model",
       "\"rss\" (regularized Stokeslet segments), \"lsbt\" (Lighthill slender-body theory), "
       "\"rft\" (resistive force theory, local) or \"none\""},
      {"fluid.viscosity", "μ [Pa·s]"},
      {"fluid.regularization", "RSS blob size ε in units of the rod radius r0"},
      {"fluid.coupling",
       "\"implicit\": the drag solved with the step (stable at any h); \"explicit\": the paper's "
       "Algorithm 1 (drag from the last step; stable only below h ≈ 2m/c, refused above)"},
      {"fluid.mobility",
       "\"auto\" (dense up to 500 nodes, and with bodies), \"dense\" or \"matrix_free\" (RSS only; "
       "takes bodies and a wall)"},
      {"fluid.far_field_tolerance",
       "dense Krylov path: relative error of one far segment–node interaction; matrix-free: the "
       "far field is accurate to the larger of this and fast_sum_tolerance"},
      {"fluid.fast_sum_tolerance",
       "matrix-free: error bound of the far-field sum at every size (sets the FMM's expansion "
       "order, single precision from 1e-4, with bodies at most 1e-5 in double; the FMM runs only "
       "where it pays, from about 20 flagella)"},
      {"fluid.mobility_reuse_tolerance",
       "RSS: the dense 𝕄, or the matrix-free operator's near corrections (where its far sum is in "
       "single precision, fast_sum_tolerance ≥ 1e-4), are extrapolated from their last assemblies "
       "between steps while their measured relative error (Frobenius) stays below this (the near "
       "corrections while their pattern of near pairs holds); 0 assembles them at every step; "
       "summary.json mobility_reuse"},
      {"fluid.solver",
       "implicit coupling: \"krylov\" (GMRES) or \"direct\" (dense LU; dense mobility only)"},
      {"fluid.krylov_tolerance", "GMRES relative residual"},
      {"fluid.krylov_rotate_preconditioner",
       "GMRES: the preconditioner kept across steps is applied in each rod's frame turned by the "
       "rod's best-fit rotation since it was built; false applies it as built. A preconditioner "
       "only: the solution and its tolerance do not change, the GMRES products do"},
      {"fluid.krylov_coarse_rebuild_period",
       "matrix-free, with krylov_rotate_preconditioner: the preconditioner's coarse level (its "
       "dense E, whose LU grows as the cube of the rods) is rebuilt at every this-many rebuilds of "
       "the preconditioner and applied in its own rotated frame between them; 0 chooses by its "
       "cost (1 up to about 150 helices, 2 at 200, 4 at 400). A preconditioner only: the solution "
       "and its tolerance do not change, the GMRES products and the time do"},
      {"contact.enabled",
       "rod–rod and self contact (paper section 2.3), of rods with the wall and the bodies, and of "
       "the bodies with each other and the wall"},
      {"contact.tolerance",
       "a contact is resolved when every distance ≥ (r_a + r_b)(1 − tolerance)"},
      {"contact.max_rounds", "solve–detect–re-solve rounds per step before a numerical failure"},
      {"gravity.acceleration", "g [m/s²], for validation cases"},
      {"solver.newton_tolerance",
       "Newton residual (a force) relative to max(EI/L², applied forces)"},
      {"solver.newton_max_iterations", "per solve; more is a numerical failure (exit 3)"},
      {"solver.jacobian_max_age",
       "steps a factorized Newton matrix may be reused (1: a new one every step)"},
      {"solver.max_step_halvings",
       "a failed step is retried as two of h/2, this many times deep (0: a failure ends the run; "
       "counted in summary.json step_reductions)"},
      {"solver.damping",
       "isotropic viscous drag per unit length [Pa·s] (validation cases with fluid.model = "
       "\"none\")"},
      {"flow_field.times",
       "simulated times [s] at which the flow on the plane is written (paper Fig. 6b); empty: "
       "none"},
      {"flow_field.origin", "a corner of the plane [m]"},
      {"flow_field.u", "first edge of the plane [m]"},
      {"flow_field.v", "second edge of the plane [m]"},
      {"flow_field.resolution", "grid points along u and along v"},
      {"rods.shape",
       "\"helix\" (the paper's geometry, section 3), \"straight\" (along −z) or \"points\""},
      {"rods.radius", "cross-section radius r0 [m]"},
      {"rods.young_modulus", "E [Pa]"},
      {"rods.poisson_ratio", "ν, in (−1, 0.5]; G = E/(2(1 + ν))"},
      {"rods.density", "ρ [kg/m³]"},
      {"rods.nodes", "N (shape = \"points\": the number of points)"},
      {"rods.axis_length", "l0 [m]: the last node is this far below base (helix, straight)"},
      {"rods.pitch", "λ [m], helix only"},
      {"rods.helix_radius", "R [m], helix only"},
      {"rods.handedness", "\"right\" or \"left\", helix only"},
      {"rods.lead_in",
       "helix only: \"within\" (l0 spans the whole rod, SPEC) or \"above\" (the helical part spans "
       "l0 below node 2; clamp edge and lead-in above it)"},
      {"rods.base", "position of node 0 [m]"},
      {"rods.clamped_nodes",
       "0, 1 or 2 leading nodes held fixed (2 also holds the first twist angle)"},
      {"rods.omega",
       "rotation rate about +z imposed on the first twist angle [rad/s]; or omega_bar, not both"},
      {"rods.omega_bar", "the same normalized: ω μ l0⁴/EI"},
      {"rods.points", "shape = \"points\": the rest shape, node by node [m]"},
      {"rods.loads", "constant point forces, e.g. [{node = 64, force = [0, 0, -1e-3]}]"},
      {"rods.loads[].node", "node of the load, from 0"},
      {"rods.loads[].force", "force [N]"},
      {"rods.body",
       "the body (from 1) whose frame holds the clamped nodes and against which the motor turns; "
       "0: none (any motion; on a \"free\" body the rods and the body swim force- and torque-free "
       "together)"},
      {"bodies.shape",
       "\"sphere\" or \"spheroid\" (no contact and no rods on it yet: contact.enabled = false)"},
      {"bodies.radius", "a [m] (a spheroid's equatorial radius)"},
      {"bodies.center", "centre at the start [m]"},
      {"bodies.motion",
       "\"fixed\", \"prescribed\" (velocity and angular_velocity) or \"free\" (force- and "
       "torque-free together with the rods on it: carried by the flow, swimming, or settling under "
       "its force)"},
      {"bodies.velocity", "U [m/s] of the centre, motion = \"prescribed\" only"},
      {"bodies.half_length",
       "a spheroid's polar semi-axis [m] along its axis (radius: the equatorial one; prolate or "
       "oblate), shape = \"spheroid\" only"},
      {"bodies.axis",
       "a spheroid's axis at the start (normalized), shape = \"spheroid\" only; it turns with the "
       "body"},
      {"bodies.angular_velocity", "Ω [rad/s] about the centre, motion = \"prescribed\" only"},
      {"bodies.force",
       "a constant force [N] on the body at its centre (e.g. weight minus buoyancy), motion = "
       "\"free\" only"},
      {"bodies.torque",
       "a constant torque [N·m] on the body about its centre, motion = \"free\" only"},
      {"bodies.surface_points",
       "regularized Stokeslets on the surface (Fibonacci points, ε = 0.3 × their spacing; drag "
       "~1.4 % low at 400, first order)"},
      {"wall.point", "a point of the plane no-slip wall [m]"},
      {"wall.normal",
       "its normal, pointing into the fluid (normalized); RSS only (dense or matrix-free "
       "mobility)"},
  };
  return m;
}

std::string Section(const std::string& key) {
  const std::string head = key.substr(0, key.find('.'));
  if (head == "rods")
    return "[[rods]] (one table per rod; `--set rods.KEY=...` on every rod, `rods.K.KEY` on rod K)";
  if (head == "bodies")
    return "[[bodies]] (optional, one table per cell body; `--set bodies.K.KEY=...`)";
  return head == "wall" ? "[wall] (optional: a plane no-slip wall)" : "[" + head + "]";
}

}  // namespace

std::string ConfigKeysMarkdown() {
  const std::vector<ConfigKey> keys = ListConfigKeys();
  std::map<std::string, bool> used;
  std::string out =
      "# Configuration keys\n\n"
      "Every key of the configuration file, generated from the field lists the reader uses\n"
      "(`src/stokesrods/io/config.cc`) and the meanings in `src/stokesrods/io/config_docs.cc`; the\n"
      "test `ConfigDocs.KeysPageIsUpToDate` fails when this page drifts (regenerate it with\n"
      "`STOKESRODS_UPDATE_DOCS=1 build/release/tests/io/io_test --gtest_filter=ConfigDocs.*`).\n"
      "`stokesrods show-config CONFIG.toml` prints a configuration with every default filled in.\n"
      "Unknown keys, wrong types and values out of range are input errors (exit 2).\n";
  std::string section;
  for (const ConfigKey& k : keys) {
    const auto meaning = Meanings().find(k.key);
    if (meaning == Meanings().end())
      throw std::logic_error("configuration key " + k.key + " has no meaning in io/config_docs.cc");
    used[k.key] = true;
    if (Section(k.key) != section) {
      section = Section(k.key);
      out += fmt::format("\n## {}\n\n| key | type | default | meaning |\n| --- | --- | --- | --- |\n", section);
    }
    out += fmt::format("| `{}` | {} | {} | {} |\n", k.key.substr(k.key.find('.') + 1), k.type,
                       k.default_value.empty() ? "unset" : "`" + k.default_value + "`", meaning->second);
  }
  for (const auto& [key, text] : Meanings())
    if (!used.count(key))
      throw std::logic_error("io/config_docs.cc describes " + key + ", which is not a configuration key");
  return out;
}

}  // namespace stokesrods
