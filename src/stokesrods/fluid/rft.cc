#include "stokesrods/fluid/rft.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "stokesrods/common/assert.h"

namespace stokesrods {
namespace {

void RequirePositive(double value, const char* what) {
  if (!(value > 0.0)) {
    throw std::invalid_argument(std::string("RFT coefficients: ") + what + " must be > 0, got " +
                                std::to_string(value));
  }
}

}  // namespace

RftCoefficients LighthillCoefficients(double viscosity, double radius, double arc_wavelength) {
  RequirePositive(viscosity, "viscosity");
  RequirePositive(radius, "radius");
  RequirePositive(arc_wavelength, "wavelength along the filament");
  const double q = 0.09 * arc_wavelength;
  const double log_term = std::log(2.0 * q / radius);
  RequirePositive(log_term, "ln(2q/r0) (filament too thick for its wavelength)");
  return {2.0 * kPi * viscosity / log_term, 4.0 * kPi * viscosity / (log_term + 0.5)};
}

RftCoefficients GrayHancockCoefficients(double viscosity, double radius, double wavelength) {
  RequirePositive(viscosity, "viscosity");
  RequirePositive(radius, "radius");
  RequirePositive(wavelength, "wavelength");
  const double log_term = std::log(2.0 * wavelength / radius);
  RequirePositive(log_term - 0.5, "ln(2λ/r0) − 1/2 (filament too thick for its wavelength)");
  return {2.0 * kPi * viscosity / (log_term - 0.5), 4.0 * kPi * viscosity / (log_term + 0.5)};
}

void AssembleRftMobility(const std::vector<HydroRod>& rods, MatX* mobility) {
  Eigen::Index total = 0;
  for (const HydroRod& rod : rods) total += rod.x->cols();
  mobility->setZero(3 * total, 3 * total);
  Eigen::Index offset = 0;
  for (const HydroRod& rod : rods) {
    SR_ASSERT(rod.rft_parallel > 0.0 && rod.rft_perpendicular > 0.0, "RFT coefficients must be > 0");
    const VecX lengths = VoronoiLengths(*rod.x);
    const Matrix3X tangents = NodeTangents(*rod.x);
    for (Eigen::Index i = 0; i < rod.x->cols(); ++i) {
      const Mat3 tt = tangents.col(i) * tangents.col(i).transpose();
      const Mat3 block =
          (tt / rod.rft_parallel + (Mat3::Identity() - tt) / rod.rft_perpendicular) / lengths(i);
      mobility->block<3, 3>(3 * (offset + i), 3 * (offset + i)) = block;
    }
    offset += rod.x->cols();
  }
}

}  // namespace stokesrods
