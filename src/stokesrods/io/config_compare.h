// Whether a finished run answers the configuration asked for now, across versions of the program:
// what a sweep's resume uses (io/sweep.h, ReadCaseRecord).
#pragma once

#include <nlohmann/json.hpp>

namespace stokesrods {

/// True when a run made from `before` (the resolved configuration in its summary.json, maybe
/// written by an older version) is the run `now` asks for (ConfigToJson of the configuration
/// today): every key `before` has is in `now` with the same value, and every key `before` lacks
/// (added to the program since) is at its default in `now`. A key `before` has and `now` lacks, a
/// section or list element only one side has, or a new key set away from its default: false.
bool SameRunSettings(const nlohmann::json& before, const nlohmann::json& now);

}  // namespace stokesrods
