// Keypoints of a rolling-shutter image moved to the middle row's moment (feature/RollingShutter.h),
// on points seen exactly as a camera whose rows are read one after another while it moves.
#include <gtest/gtest.h>

#include <mrpt/poses/Lie/SE.h>

#include <random>

#include "mrpt_yesslam/feature/RollingShutter.h"
#include "mrpt_yesslam/io/RgbdCamera.h"

using namespace mrpt_yesslam;

namespace
{
// The camera at readout fraction a (-0.5 = first row, +0.5 = last) in the middle row's camera.
mrpt::poses::CPose3D rowCamera(const mrpt::poses::CPose3D& overReadout, double a)
{
	auto v = mrpt::poses::Lie::SE<3>::log(overReadout);
	for (int k = 0; k < 6; k++) v[k] *= a;
	return mrpt::poses::Lie::SE<3>::exp(v);
}

void expectUnrolled(const mrpt::img::TCamera& cam)
{
	const CPinholeCamera K(cam);
	// 28 ms of a hand-held camera: 20 deg/s about y, 10 deg/s about x, 0.4 m/s sideways and forward.
	const mrpt::poses::CPose3D overReadout(0.008, 0.002, 0.006, mrpt::DEG2RAD(0.56), mrpt::DEG2RAD(0.28), 0);
	std::mt19937 rng(5);
	std::uniform_real_distribution<double> uu(20, 620), vv(20, 460), zz(0.8, 5.0);
	TFeatures f;
	std::vector<cv::Point2d> truth;
	std::vector<double> trueDepth;
	while (f.keypoints.size() < 300)
	{
		// A point seen at (u, v, z) by the middle row's camera (the global-shutter image).
		const double u0 = uu(rng), v0 = vv(rng), z0 = zz(rng);
		const cv::Point3d X = K.backProject(u0, v0, z0);
		// Where the rolling shutter saw it: the row read when the camera had moved on (fixed point).
		double u = u0, v = v0, z = z0;
		bool ok = true;
		for (int it = 0; it < 20 && ok; it++)
		{
			const double a = K.distort(u, v).y / cam.nrows - 0.5;
			mrpt::math::TPoint3D Xr;
			rowCamera(overReadout, a).inverseComposePoint({X.x, X.y, X.z}, Xr);
			ok = K.project(Xr.x, Xr.y, Xr.z, u, v) && K.inImage(u, v);
			z = Xr.z;
		}
		if (!ok) continue;
		const bool withDepth = f.keypoints.size() % 5 != 0;  // a fifth without depth (far or missing)
		f.keypoints.emplace_back(cv::Point2f(static_cast<float>(u), static_cast<float>(v)), 8.f);
		f.depth.push_back(withDepth ? static_cast<float>(z) : 0.f);
		truth.emplace_back(u0, v0);
		trueDepth.push_back(withDepth ? z0 : 0);
	}
	f.dynamic.assign(f.keypoints.size(), false);
	const auto worst = [&](bool depthOnly, double& px, double& dz)
	{
		px = dz = 0;
		for (std::size_t i = 0; i < f.keypoints.size(); i++)
		{
			if ((f.depth[i] > 0) != depthOnly) continue;
			px = std::max(px, std::hypot(f.keypoints[i].pt.x - truth[i].x, f.keypoints[i].pt.y - truth[i].y));
			if (depthOnly) dz = std::max(dz, std::abs(f.depth[i] - trueDepth[i]));
		}
	};
	double px = 0, dz = 0, pxFar = 0, unused = 0;
	worst(true, px, dz);
	EXPECT_GT(px, 2.0) << "the rolling shutter moves keypoints by pixels";
	unrollShutter(f, K, overReadout);
	worst(true, px, dz);
	worst(false, pxFar, unused);
	EXPECT_LT(px, 0.02) << "largest keypoint error with depth, px";
	EXPECT_LT(dz, 1e-4) << "largest depth error, m";
	// Without depth only the rotation is undone: the translation's part (up to 4 mm at 0.8 m) stays.
	EXPECT_LT(pxFar, 6.0);
	std::size_t moved = 0;
	for (std::size_t i = 0; i < f.keypoints.size(); i++) moved += trueDepth[i] == 0;
	EXPECT_GT(moved, 50u);
}
}  // namespace

TEST(RollingShutter, KeypointsAreMovedToTheMiddleRowsMoment)
{
	expectUnrolled(tumCameraByName("fr3").intrinsics);
}

// TUM fr1's published calibration, with its distortion.
TEST(RollingShutter, RowTimesAreTheRecordedRowsThroughTheLensDistortion)
{
	expectUnrolled(tumCameraByName("fr1").intrinsics);
}
