// The wall's part of Regularized Stokeslet Segments (issue 11): with a plane no-slip wall every
// segment of rss.h carries its regularized image system, A = A_free + A_images, the images' part
// integrated by StokesletSegmentWallImages (wall.h). The free part stays rss.cc's (closed forms,
// the fast paths); these add the rest.
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/hydrodynamics.h"

namespace stokesrods {

/// mobility += the images' part of 𝕄 = A Λ⁻¹ (3M × 3M) for params.wall [m/(N·s)]; each
/// segment–node pair to params.far_field_tolerance as the free part (0: round-off).
/// (StokesletSegmentWallImages with that tolerance; the rows below too.)
void AddRssWallImages(const FluidParams& params, const std::vector<HydroRod>& rods,
                      MatX* mobility);

/// The images' part of RssVelocityAt: the flow the wall adds at `point` [m/s].
Vec3 RssWallImageVelocityAt(const FluidParams& params, const std::vector<HydroRod>& rods,
                            const VecX& nodal_forces, const Vec3& point);

/// The images' part of the velocity at `point` per nodal force of the rods (f = F/Λ on the
/// segments): a 3 × 3M row block, u = row · F [m/(N·s)].
MatX RssWallImageRow(const FluidParams& params, const std::vector<HydroRod>& rods,
                     const Vec3& point);

}  // namespace stokesrods
