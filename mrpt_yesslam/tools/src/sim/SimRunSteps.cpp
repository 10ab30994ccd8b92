#include "SimRunSteps.h"
#include "mrpt_yesslam/sim/CSequenceSimulator.h"

#include <opencv2/imgproc.hpp>

#include "mrpt_yesslam/geometry/CPinholeCamera.h"

using mrpt::poses::CPose3D;

namespace mrpt_yesslam::sim_detail
{
// Pixels covered by an object's boxes if nothing occluded them (its faces rasterised).
std::size_t unoccludedPixels(const CSimWorld& world, int idx, const CPose3D& Twc, const TRgbdCamera& cam,
							 cv::Mat& scratch)
{
	scratch.setTo(0);
	const CPose3D Tcw = -Twc;
	const CPinholeCamera K(cam.intrinsics);
	static const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {3, 0, 4, 7}};
	for (const auto& [pose, b] : world.worldBoxes(idx))
	{
		cv::Point pts[8];
		bool front[8];
		for (int c = 0; c < 8; c++)
		{
			const mrpt::math::TPoint3D local((c == 1 || c == 2 || c == 5 || c == 6 ? 0.5 : -0.5) * b.sx,
											 (c == 2 || c == 3 || c == 6 || c == 7 ? 0.5 : -0.5) * b.sy,
											 (c >= 4 ? 0.5 : -0.5) * b.sz);
			const auto pc = Tcw.composePoint(pose.composePoint(local));
			front[c] = pc.z > 0.05;
			double u = 0, v = 0;
			if (front[c]) K.project(pc.x, pc.y, pc.z, u, v);
			pts[c] = front[c] ? cv::Point(static_cast<int>(u), static_cast<int>(v)) : cv::Point();
		}
		for (const auto& f : faces)
		{
			if (!(front[f[0]] && front[f[1]] && front[f[2]] && front[f[3]])) continue;
			const cv::Point poly[4] = {pts[f[0]], pts[f[1]], pts[f[2]], pts[f[3]]};
			cv::fillConvexPoly(scratch, poly, 4, cv::Scalar(255));
		}
	}
	return static_cast<std::size_t>(cv::countNonZero(scratch));
}
}  // namespace mrpt_yesslam::sim_detail

namespace mrpt_yesslam
{
mrpt::img::TCamera openGlIntrinsics(const mrpt::img::TCamera& K)
{
	// CFBORender samples pixel k at image coordinate k + 0.5 (OpenGL's pixel centres), while TUM
	// and our tracking put pixel centres at integers: rendered with the true cx, cy every image
	// came out half a pixel off its own calibration (tests/sim measures box edges placed at
	// fractional pixel positions), which bent the map wherever depth and pixels were combined.
	mrpt::img::TCamera g = K;
	g.cx(K.cx() + 0.5);
	g.cy(K.cy() + 0.5);
	return g;
}
}  // namespace mrpt_yesslam
