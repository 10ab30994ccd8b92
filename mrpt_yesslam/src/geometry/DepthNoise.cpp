#include "mrpt_yesslam/geometry/DepthNoise.h"

#include <mrpt/config/CConfigFileBase.h>

namespace mrpt_yesslam
{
COptionTable TDepthNoise::table()
{
	COptionTable t("Camera");
	t.real("depthNoise", depthNoise, 0, 1,
		   "the depth sensor's error at 1 m, sigma_z = depthNoise x z^depthNoiseExponent (m), one model for the pose "
		   "solve, bundle adjustment (x scaleFactor^octave), "
		   "point fusion, see-through culling and the loop's relative pose; 0 = depth is not a measurement "
		   "(reprojection only, eq. 7 and 24)");
	t.real("depthNoiseExponent", depthNoiseExponent, 1, 4,
		   "how the depth error grows with z: 2 = structured light's random disparity noise alone, 2.5 = with the "
		   "disparity distortion and far-depth bias that "
		   "grow faster (measured better on the real Xtion frames and the real-sensor sims, as good on the Kinect "
		   "frames)");
	t.real("farDepth", farDepth, 0, 20,
		   "beyond this depth (m) a keypoint's depth is not a measurement in the pose solve, bundle adjustment and the "
		   "loop's final pose solve: the "
		   "keypoint counts by its pixel alone, and in bundle adjustment a point no keyframe measures nearer keeps its "
		   "position; 0 = every depth "
		   "(measured: off by default, docs/benchmarks.md)");
	return t;
}
}  // namespace mrpt_yesslam
