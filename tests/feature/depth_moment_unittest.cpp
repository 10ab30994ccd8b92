// Keypoint depth moved to the colour image's moment (feature/DepthMoment.h), on a depth image of a
// known slanted wall rendered for a camera that moved between the two images.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/feature/DepthMoment.h"

using namespace mrpt_yesslam;

namespace
{
// The wall n.X = d in the colour camera's frame; depth along the undistorted pixel (u, v)'s ray of a
// camera at pose `cam` in that frame.
double wallDepth(const CPinholeCamera& K, const mrpt::poses::CPose3D& cam, double u, double v)
{
	const mrpt::math::TVector3D n(0.25, -0.1, 1.0);
	const double d = 2.5;
	const auto R = cam.getRotationMatrix();
	// In the moved camera: (R^T n).X = d - n.t
	const double nx = R(0, 0) * n.x + R(1, 0) * n.y + R(2, 0) * n.z, ny = R(0, 1) * n.x + R(1, 1) * n.y + R(2, 1) * n.z,
				 nz = R(0, 2) * n.x + R(1, 2) * n.y + R(2, 2) * n.z;
	const double dd = d - (n.x * cam.x() + n.y * cam.y() + n.z * cam.z());
	const double rx = (u - K.cx()) / K.fx(), ry = (v - K.cy()) / K.fy();
	return dd / (nx * rx + ny * ry + nz);
}

// Raw (distorted) depth image of the wall for a camera at `cam`.
cv::Mat renderWall(const mrpt::img::TCamera& cam, const mrpt::poses::CPose3D& pose)
{
	const CPinholeCamera K(cam);
	std::vector<cv::Point2f> px;
	for (int y = 0; y < 480; y++)
		for (int x = 0; x < 640; x++) px.emplace_back(static_cast<float>(x), static_cast<float>(y));
	K.undistort(px);
	cv::Mat depth(480, 640, CV_32F);
	for (int y = 0; y < 480; y++)
		for (int x = 0; x < 640; x++)
		{
			const auto& p = px[static_cast<std::size_t>(y * 640 + x)];
			depth.at<float>(y, x) = static_cast<float>(wallDepth(K, pose, p.x, p.y));
		}
	return depth;
}

void expectCorrected(const mrpt::img::TCamera& cam)
{
	const CPinholeCamera K(cam);
	// 15 ms of a hand-held camera: 20 deg/s about y and 5 deg/s about x, 0.4 m/s mostly forward.
	const mrpt::poses::CPose3D moved(0.002, -0.001, 0.006, mrpt::DEG2RAD(0.3), mrpt::DEG2RAD(0.075), 0);
	const cv::Mat depth = renderWall(cam, moved);
	TFeatures f;
	for (double v = 40.3; v < 440; v += 37.1)
		for (double u = 40.7; u < 600; u += 41.3)
		{
			f.keypoints.emplace_back(cv::Point2f(static_cast<float>(u), static_cast<float>(v)), 8.f);
			const cv::Point2d raw = K.distort(u, v);
			f.depth.push_back(COrbExtractor::depthAt(depth, raw.x, raw.y));  // as the extractor reads it
		}
	f.dynamic.assign(f.keypoints.size(), false);
	double before = 0, after = 0;
	for (std::size_t i = 0; i < f.keypoints.size(); i++)
		before = std::max(before, std::abs(f.depth[i] - wallDepth(K, {}, f.keypoints[i].pt.x, f.keypoints[i].pt.y)));
	EXPECT_EQ(moveDepthToColourMoment(f, depth, K, moved), 0u) << "every keypoint keeps its depth on a smooth wall";
	std::size_t withDepth = 0;
	for (std::size_t i = 0; i < f.keypoints.size(); i++)
	{
		withDepth += f.depth[i] > 0;
		after = std::max(after, std::abs(f.depth[i] - wallDepth(K, {}, f.keypoints[i].pt.x, f.keypoints[i].pt.y)));
	}
	EXPECT_EQ(withDepth, f.keypoints.size());
	EXPECT_GT(before, 0.01) << "the depth image's own moment is centimetres off";
	EXPECT_LT(after, 0.0005) << "largest error at the colour image's moment, m";
}
}  // namespace

TEST(DepthMoment, KeypointDepthIsCarriedToTheColourImagesMoment)
{
	mrpt::img::TCamera cam;
	cam.ncols = 640;
	cam.nrows = 480;
	cam.setIntrinsicParamsFromValues(540, 540, 320, 240);
	expectCorrected(cam);
}

TEST(DepthMoment, AlsoThroughLensDistortion)
{
	// The depth image is as recorded (distorted); the keypoints are undistorted.
	mrpt::img::TCamera cam;
	cam.ncols = 640;
	cam.nrows = 480;
	cam.setIntrinsicParamsFromValues(540, 540, 320, 240);
	cam.dist[0] = 0.2;
	cam.dist[1] = -0.5;
	cam.dist[2] = 0.001;
	cam.dist[3] = -0.002;
	expectCorrected(cam);
}
