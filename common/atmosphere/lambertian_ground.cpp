#include "common/atmosphere/lambertian_ground.h"

#include "common/core/constants.h"
#include "common/sampling/warps.h"

namespace skyfarm {

double LambertianGround::brdf(double lambda_nm, double cos_theta_i) const {
  return cos_theta_i > 0.0 ? albedo(lambda_nm) * kInvPi : 0.0;
}

glm::dvec3 LambertianGround::sample_direction(const glm::dvec3& n, double u1, double u2, double* pdf) const {
  const glm::dvec3 local = square_to_cosine_hemisphere({u1, u2});
  *pdf = square_to_cosine_hemisphere_pdf(local);
  return Frame(n).to_world(local);
}

}  // namespace skyfarm
