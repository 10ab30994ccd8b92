#include "mrpt_yesslam/geometry/RelativeMotion.h"

#include <mrpt/poses/Lie/SE.h>

namespace mrpt_yesslam
{
mrpt::poses::CPose3D scaledTwist(const mrpt::math::CVectorFixedDouble<6>& twist, double s)
{
	mrpt::poses::Lie::SE<3>::tangent_vector v;
	for (int k = 0; k < 6; k++) v[k] = twist[k] * s;
	return mrpt::poses::Lie::SE<3>::exp(v);
}

mrpt::poses::CPose3D scaleMotion(const mrpt::poses::CPose3D& motion, double s)
{
	return scaledTwist(mrpt::poses::Lie::SE<3>::log(motion), s);
}
}  // namespace mrpt_yesslam
