#include "mrpt_yesslam/geometry/DepthNoise.h"

#include <mrpt/config/CConfigFileBase.h>

namespace mrpt_yesslam
{
COptionTable TDepthNoise::table()
{
	COptionTable t("Camera");
	t.real(
		"depthNoise", depthNoise, 0, 1,
		"the depth sensor's noise, sigma_z = depthNoise x z^2 (m), one model for the pose solve, bundle adjustment (x scaleFactor^octave), "
		"point fusion, see-through culling and the loop's relative pose; 0 = depth is not a measurement (reprojection only, eq. 7 and 24)");
	return t;
}
}  // namespace mrpt_yesslam
