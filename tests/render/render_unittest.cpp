// Headless rendering of .3Dscene files through CFBORender (EGL).
#include <gtest/gtest.h>
#include <mrpt/opengl/CBox.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/COpenGLScene.h>

#include <opencv2/imgcodecs.hpp>

#include "TestUtils.h"
#include "mrpt_yesslam/render/SceneRenderer.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

namespace
{
std::string writeBoxScene(const TempDir& d)
{
	mrpt::opengl::COpenGLScene scene;
	auto box = mrpt::opengl::CBox::Create(mrpt::math::TPoint3D(-1, -1, 0), mrpt::math::TPoint3D(1, 1, 1));
	box->setColor_u8(200, 30, 30);
	scene.insert(box);
	scene.insert(mrpt::opengl::CGridPlaneXY::Create(-5, 5, -5, 5, 0, 1));
	const std::string path = d / "box.3Dscene";
	EXPECT_TRUE(scene.saveToFile(path));
	return path;
}
}  // namespace

TEST(Render, SceneFileToPngIsNotBlank)
{
	TempDir d("render");
	const std::string scene = writeBoxScene(d);
	TRenderOptions o;
	o.width = 320;
	o.height = 240;
	const double share = renderSceneFileToPng(scene, d / "box.png", o);
	EXPECT_GT(share, 0.02);
	const cv::Mat img = cv::imread(d / "box.png", cv::IMREAD_COLOR);
	ASSERT_EQ(img.cols, 320);
	ASSERT_EQ(img.rows, 240);
	// The red box is visible: pixels with strong red and little green/blue.
	int red = 0;
	for (int y = 0; y < img.rows; y++)
		for (int x = 0; x < img.cols; x++)
		{
			const auto p = img.at<cv::Vec3b>(y, x);
			red += p[2] > 120 && p[1] < 80 && p[0] < 80;
		}
	EXPECT_GT(red, 200);

	// Looking away from everything gives a blank picture, which the share detects.
	o.lookAt = mrpt::math::TPoint3D(500, 500, 500);
	o.distance = 1.0;
	o.elevationDeg = -89;
	EXPECT_LT(renderSceneFileToPng(scene, d / "away.png", o), 0.001);
}

TEST(Render, BadSceneFiles)
{
	TempDir d("render");
	expectInputError([&] { renderSceneFileToPng(d / "missing.3Dscene", d / "x.png", {}); }, {"missing.3Dscene", "not found"});
	writeText(d / "junk.3Dscene", "not a scene at all");
	expectInputError([&] { renderSceneFileToPng(d / "junk.3Dscene", d / "x.png", {}); }, {"junk.3Dscene", "not a readable .3Dscene"});
}
