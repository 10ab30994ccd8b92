// CBoxRaycaster, yesslam-sim's renderer: pixel centres at integer coordinates, exact depth, the
// nearest box wins, and the same images as MRPT's own renderer gives for the simulated office.
#include <gtest/gtest.h>
#include <mrpt/opengl/CFBORender.h>
#include <mrpt/opengl/COpenGLScene.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "mrpt_yesslam/io/RgbdCamera.h"
#include "mrpt_yesslam/sim/CBoxRaycaster.h"
#include "mrpt_yesslam/sim/CSequenceSimulator.h"
#include "mrpt_yesslam/sim/CSimWorld.h"

using namespace mrpt_yesslam;
using mrpt::poses::CPose3D;

namespace
{
mrpt::img::TCamera fr3()
{
	return tumCameraByName("fr3").intrinsics;
}

// A thin box facing the camera (at the origin, looking along +z) covering image columns
// [u0, u1] and rows [v0, v1] (fractional image coordinates) at depth z.
TRayBox screenBox(double u0, double v0, double u1, double v1, double z, uint16_t id)
{
	const auto K = fr3();
	auto x = [&](double u) { return (u - K.cx()) * z / K.fx(); };
	auto y = [&](double v) { return (v - K.cy()) * z / K.fy(); };
	TRayBox b;
	b.pose = CPose3D((x(u0) + x(u1)) / 2, (y(v0) + y(v1)) / 2, z + 5e-5, 0, 0, 0);
	b.sx = x(u1) - x(u0);
	b.sy = y(v1) - y(v0);
	b.sz = 1e-4;  // thin: a ray just off the front face would otherwise hit a side
	b.id = id;
	return b;
}

// The camera of the simulated office: at the near end of the room looking along +x (optical
// frame x right, y down).
CPose3D officeCamera(double dx)
{
	mrpt::math::CMatrixDouble33 R;
	const double rows[3][3] = {{0, 0, 1}, {-1, 0, 0}, {0, -1, 0}};  // columns: camera x, y, z in the world
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) R(i, j) = rows[i][j];
	mrpt::math::CVectorFixedDouble<3> t;
	t[0] = 1.8 + dx;
	t[1] = 2.5;
	t[2] = 1.3;
	return CPose3D(R, t);
}
}  // namespace

TEST(Raycaster, PixelCentresAreAtIntegerCoordinates)
{
	// Box edges at fractional positions e around column/row 300 (bottom/right) and 100
	// (top/left): pixel 300 / 100 is covered exactly when the edge passes its centre.
	const CBoxRaycaster rc;
	cv::Mat bgr, depth, inst;
	for (double e : {-0.3, -0.1, 0.1, 0.3})
	{
		SCOPED_TRACE(e);
		rc.render({screenBox(100 + e, 100 + e, 300 + e, 300 + e, 2.0, 7)}, CPose3D(), fr3(), bgr, depth, inst);
		auto covered = [&](int v, int u) { return inst.at<uint16_t>(v, u) == 7; };
		EXPECT_EQ(covered(300, 200), e > 0) << "bottom edge";
		EXPECT_EQ(covered(200, 300), e > 0) << "right edge";
		EXPECT_EQ(covered(100, 200), e < 0) << "top edge";
		EXPECT_EQ(covered(200, 100), e < 0) << "left edge";
	}
}

TEST(Raycaster, DepthIsExactOnATiltedPlane)
{
	// A large box tilted 35 degrees about the camera's y axis: its front face is the plane
	// n.p = d; every pixel's depth must be the ray's intersection with it.
	TRayBox b;
	b.pose = CPose3D(0.2, -0.1, 3.0, 0, 35 * M_PI / 180, 0);
	b.sx = b.sy = 8;
	b.sz = 0.2;
	b.id = 3;
	const CBoxRaycaster rc;
	cv::Mat bgr, depth, inst;
	rc.render({b}, CPose3D(), fr3(), bgr, depth, inst);
	const auto R = b.pose.getRotationMatrix();
	const double n[3] = {R(0, 2), R(1, 2), R(2, 2)};                                   // box z axis in the camera frame
	const double d = n[0] * b.pose.x() + n[1] * b.pose.y() + n[2] * b.pose.z() - 0.1;  // the face towards the camera
	const auto K = fr3();
	double worst = 0;
	std::size_t hits = 0;
	for (int v = 0; v < depth.rows; v += 7)
		for (int u = 0; u < depth.cols; u += 7)
		{
			if (inst.at<uint16_t>(v, u) != 3) continue;
			hits++;
			const double rx = (u - K.cx()) / K.fx(), ry = (v - K.cy()) / K.fy();
			const double z = d / (n[0] * rx + n[1] * ry + n[2]);
			worst = std::max(worst, std::abs(depth.at<float>(v, u) - z));
		}
	ASSERT_GT(hits, 5000u);
	EXPECT_LT(worst, 2e-6) << "ray-plane depth error (m)";  // float rounding only
}

TEST(Raycaster, NearestBoxWinsAndNothingIsEmpty)
{
	const CBoxRaycaster rc;
	cv::Mat bgr, depth, inst;
	// Box 2 (nearer) overlaps box 1's right half; listed after it and before it: same result.
	for (bool nearFirst : {false, true})
	{
		const TRayBox far = screenBox(100, 100, 400, 300, 3.0, 1), near = screenBox(250, 150, 500, 250, 1.5, 2);
		rc.render(nearFirst ? std::vector<TRayBox>{near, far} : std::vector<TRayBox>{far, near}, CPose3D(), fr3(), bgr,
				  depth, inst);
		EXPECT_EQ(inst.at<uint16_t>(200, 150), 1);
		EXPECT_NEAR(depth.at<float>(200, 150), 3.0, 1e-5);
		EXPECT_EQ(inst.at<uint16_t>(200, 300), 2);
		EXPECT_NEAR(depth.at<float>(200, 300), 1.5, 1e-5);
		EXPECT_EQ(inst.at<uint16_t>(200, 450), 2);
		EXPECT_EQ(inst.at<uint16_t>(400, 300), 0);
		EXPECT_EQ(depth.at<float>(400, 300), 0.0f);
		EXPECT_EQ(bgr.at<cv::Vec3b>(400, 300), cv::Vec3b(0, 0, 0));
	}
	// A box behind the camera is not seen.
	rc.render({screenBox(100, 100, 400, 300, -3.0, 5)}, CPose3D(), fr3(), bgr, depth, inst);
	EXPECT_EQ(cv::countNonZero(inst), 0);
}

TEST(Raycaster, SameImagesAsMrptsRendererForTheOffice)
{
	// The simulated office with two walkers, rendered by MRPT's CFBORender (from world.scene(),
	// which is also what scene.3Dscene holds) and by the ray caster: same surfaces, textures and
	// light. CFBORender's depth is a +-0.4 % sawtooth around the truth, and both renderers take
	// one sample per pixel, so silhouettes may differ by a pixel.
	CSimWorld world(1);
	world.addWalkingPerson(
		{mrpt::math::TPoint2D(4.4, 1.2), mrpt::math::TPoint2D(2.95, 2.3), mrpt::math::TPoint2D(4.4, 3.8)}, 0.8, 0.0);
	world.addWalkingPerson({mrpt::math::TPoint2D(3.5, 0.7), mrpt::math::TPoint2D(3.6, 4.3)}, 1.1, 1.0);
	const auto K = fr3();
	mrpt::opengl::CFBORender fbo(static_cast<int>(K.ncols), static_cast<int>(K.nrows));
	const CBoxRaycaster rc;
	for (double t : {0.5, 2.0})
	{
		SCOPED_TRACE(t);
		world.setTime(t);
		const CPose3D Twc = officeCamera(0.2 * t);
		auto scene = world.scene(true);
		scene->getViewport()->setViewportClipDistances(0.2f, 10.0f);
		auto& cam = fbo.getCamera(*scene);
		cam.set6DOFMode(true);
		cam.setProjectiveFromPinhole(openGlIntrinsics(K));
		cam.setPose(Twc);
		mrpt::img::CImage glImg;
		mrpt::math::CMatrixFloat glDepth;
		fbo.render_RGBD(*scene, glImg, glDepth);
		cv::Mat gl = glImg.asCvMatRef();
		if (gl.channels() == 4) cv::cvtColor(gl, gl, cv::COLOR_BGRA2BGR);
		cv::Mat bgr, depth, inst;
		rc.render(world.rayBoxes(), Twc, K, bgr, depth, inst);
		// Compared over 7x7 neighbourhoods: the textures' fine grain makes single texels differ
		// wherever the two pick the neighbouring texel; layout and light show at this scale.
		cv::Mat bgrBlur, glBlur;
		cv::blur(bgr, bgrBlur, {7, 7});
		cv::blur(gl, glBlur, {7, 7});

		std::size_t both = 0, depthOk = 0, n = 0, colourOk = 0;
		double colourDiff = 0;
		for (int v = 0; v < depth.rows; v++)
			for (int u = 0; u < depth.cols; u++)
			{
				const float a = depth.at<float>(v, u), g = glDepth(v, u);
				if (a <= 0 || g <= 0) continue;
				both++;
				if (std::abs(a - g) > 0.01f * a) continue;  // another surface (silhouette pixel)
				depthOk++;
				const cv::Vec3b p = bgrBlur.at<cv::Vec3b>(v, u), q = glBlur.at<cv::Vec3b>(v, u);
				const int diff = std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]);
				colourDiff += diff;
				colourOk += diff <= 6;
				n++;
			}
		ASSERT_GT(both, 300000u);
		EXPECT_GT(depthOk, both * 99 / 100) << "surfaces differ";
		EXPECT_LT(colourDiff / static_cast<double>(n), 6.0) << "mean colour difference (sum over BGR)";
		EXPECT_GT(colourOk, n * 90 / 100) << "texture layout or light differ";
	}
}
