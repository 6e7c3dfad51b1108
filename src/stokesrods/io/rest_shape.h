// A rod's rest shape from its configuration, and the checks that it is a shape the rod model can
// start from (every edge a finite, representable direction; a first reference frame exists).
#pragma once

#include <string>

#include "stokesrods/common/types.h"
#include "stokesrods/io/config.h"

namespace stokesrods {

/// The nodes of a helix, a straight rod or the given points (SPEC [[rods]]).
Matrix3X RestShape(const RodConfig& rod);

/// Throws ConfigError (naming `key` = "rods.K", with ".points[i]" for a points rod and ".base" or
/// ".axis_length" for a generated shape) unless the rest shape `x` of that rod:
///   - has finite coordinates within ±kMaxCoordinate, so that squares and cubes of lengths stay
///     finite;
///   - has every edge longer than the round-off of its end points: no point lies farther from the
///     origin than kMaxPositionOverEdge shortest edges, so every edge keeps 8 significant digits;
///   - never turns back on itself (a 180° turn has no curvature binormal and no parallel
///     transport of the reference frame).
void CheckRestShape(const std::string& file, const std::string& key, const RodConfig& rod,
                    const Matrix3X& x);

constexpr double kMaxCoordinate = 1e100;        // m
constexpr double kMaxPositionOverEdge = 1e8;    // 16 digits of a double less 8 kept in an edge

}  // namespace stokesrods
