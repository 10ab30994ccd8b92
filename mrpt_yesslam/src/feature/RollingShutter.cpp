#include "mrpt_yesslam/feature/RollingShutter.h"

#include <mrpt/poses/Lie/SE.h>

#include "mrpt_yesslam/geometry/RelativeMotion.h"

namespace mrpt_yesslam
{
void unrollShutter(TFeatures& f, const CPinholeCamera& K, const mrpt::poses::CPose3D& motionOverReadout)
{
	if (K.height() <= 0) return;
	const auto twist = mrpt::poses::Lie::SE<3>::log(motionOverReadout);
	// A keypoint without depth: far enough that translation moves it by less than a hundredth of a
	// pixel at hand-held speeds, so only the rotation does.
	constexpr double farDepth = 1e4;
	for (std::size_t i = 0; i < f.keypoints.size(); i++)
	{
		cv::KeyPoint& kp = f.keypoints[i];
		// The row as recorded (distorted) tells when it was read.
		const double row = K.distort(kp.pt.x, kp.pt.y).y;
		const double a = row / K.height() - 0.5;                       // readouts after the middle row
		const mrpt::poses::CPose3D rowCamera = scaledTwist(twist, a);  // in the middle row's camera
		const bool hasDepth = f.depth[i] > 0;
		const cv::Point3d X = K.backProject(kp.pt.x, kp.pt.y, hasDepth ? f.depth[i] : farDepth);
		mrpt::math::TPoint3D Xm;
		rowCamera.composePoint({X.x, X.y, X.z}, Xm);
		double u = 0, w = 0;
		if (!K.project(Xm.x, Xm.y, Xm.z, u, w) || !K.inImage(u, w)) continue;
		kp.pt = cv::Point2f(static_cast<float>(u), static_cast<float>(w));
		if (hasDepth) f.depth[i] = static_cast<float>(Xm.z);
	}
}
}  // namespace mrpt_yesslam
