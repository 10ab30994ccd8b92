// Headless rendering of .3Dscene files through CFBORender (EGL).
#include <gtest/gtest.h>
#include <mrpt/opengl/CBox.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/COpenGLScene.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "TestUtils.h"
#include "mrpt_yesslam/render/SceneRenderer.h"
#include "mrpt_yesslam/sim/CSimWorld.h"
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
	EXPECT_GT(share, 0.005);
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

TEST(Render, ASimulatedRoomIsFramedFromAboveAndSeenFromInside)
{
	// Issue 18 item 6: the simulator's room (boxes placed inside posed sets) came out centred on the
	// world origin, so a top view cut it in half; and from outside it is a closed box. Framed now
	// from any elevation, and --hide ceiling,wall shows the furniture inside.
	TempDir d("render_room");
	const CSimWorld world(5);
	ASSERT_TRUE(world.scene()->saveToFile(d / "room.3Dscene"));
	auto extent = [](const cv::Mat& img, const cv::Vec3b& bg)
	{
		cv::Mat diff;
		cv::absdiff(img, cv::Scalar(bg[0], bg[1], bg[2]), diff);
		cv::Mat grey;
		cv::cvtColor(diff, grey, cv::COLOR_BGR2GRAY);
		return cv::boundingRect(grey > 8);
	};
	TRenderOptions o;
	o.width = 320;
	o.height = 240;
	for (const double elevation : {30.0, 89.0, 90.0})
	{
		o.elevationDeg = elevation;
		renderSceneFileToPng(d / "room.3Dscene", d / "top.png", o);
		const cv::Mat img = cv::imread(d / "top.png", cv::IMREAD_COLOR);
		const cv::Rect r = extent(img, {255, 255, 255});
		SCOPED_TRACE(elevation);
		EXPECT_GT(r.x, 0);
		EXPECT_GT(r.y, 0);
		EXPECT_LT(r.x + r.width, img.cols);
		EXPECT_LT(r.y + r.height, img.rows);
		EXPECT_NEAR(r.x + 0.5 * r.width, 0.5 * img.cols, 0.1 * img.cols);
		EXPECT_NEAR(r.y + 0.5 * r.height, 0.5 * img.rows, 0.1 * img.rows);
	}
	// From above, the centre of the picture is the ceiling; with the ceiling hidden, the floor.
	o.elevationDeg = 89;
	renderSceneFileToPng(d / "room.3Dscene", d / "closed.png", o);
	o.hide = {"ceiling", "wall"};
	renderSceneFileToPng(d / "room.3Dscene", d / "open.png", o);
	const cv::Vec3b closed = cv::imread(d / "closed.png", cv::IMREAD_COLOR).at<cv::Vec3b>(120, 160);
	const cv::Vec3b open = cv::imread(d / "open.png", cv::IMREAD_COLOR).at<cv::Vec3b>(120, 160);
	EXPECT_GT(closed[0] + closed[1] + closed[2], 3 * 190) << "the ceiling is light";
	EXPECT_LT(open[0] + open[1] + open[2], 3 * 150) << "the floor is dark";
}
