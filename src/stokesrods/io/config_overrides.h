// The command line's --set KEY=VALUE overrides (SPEC: `stokesrods run --set`), applied to the
// parsed TOML of a configuration before it is read. Internal to io/ (config.cc).
#pragma once

#include <string>

#include <toml++/toml.h>

namespace stokesrods {

/// Sets KEY (dotted: "fluid.model", "rods.2.length" for the second [[rods]] table, "rods.length"
/// for every one; [[bodies]] alike) to VALUE (TOML; a bare word is a string) in `root`. Setting
/// one of run.duration / run.t_bar_end (or omega / omega_bar) removes the other. Throws
/// ConfigError naming `file` and the key on a malformed assignment or a missing table.
void ApplyOverride(toml::table* root, const std::string& assignment, const std::string& file);

}  // namespace stokesrods
