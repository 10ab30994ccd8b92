// Headless rendering of .3Dscene files through CFBORender (EGL).
#include <gtest/gtest.h>
#include <mrpt/opengl/CBox.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloudColoured.h>

#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "TestUtils.h"
#include "mrpt_yesslam/dense/DenseMapExport.h"
#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/system/SlamExport.h"
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
	expectInputError([&] { renderSceneFileToPng(d / "missing.3Dscene", d / "x.png", {}); },
					 {"missing.3Dscene", "not found"});
	writeText(d / "junk.3Dscene", "not a scene at all");
	expectInputError([&] { renderSceneFileToPng(d / "junk.3Dscene", d / "x.png", {}); },
					 {"junk.3Dscene", "not a readable .3Dscene"});
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
	o.hide = std::vector<std::string>{"ceiling", "wall"};
	renderSceneFileToPng(d / "room.3Dscene", d / "open.png", o);
	const cv::Vec3b closed = cv::imread(d / "closed.png", cv::IMREAD_COLOR).at<cv::Vec3b>(120, 160);
	const cv::Vec3b open = cv::imread(d / "open.png", cv::IMREAD_COLOR).at<cv::Vec3b>(120, 160);
	EXPECT_GT(closed[0] + closed[1] + closed[2], 3 * 190) << "the ceiling is light";
	EXPECT_LT(open[0] + open[1] + open[2], 3 * 150) << "the floor is dark";
}

TEST(Render, AMapsDefaultPictureShowsItsCloudAndPathFilledAndTheLegendOverTheOctoMap)
{
	// Issue 30 item 9: a yesslam map.3Dscene: a dense cloud (a 4 x 3 m green floor with two stray
	// points 40 m away, as real depth leaves), the OctoMap over it (blue-ish voxels of one label),
	// a 2 m camera path. The default picture shows the cloud and a visible path (not the voxels
	// that cover the cloud), fills the frame despite the stray points, and the legend of the
	// OctoMap's labels is drawn on the picture, the same from any elevation.
	TempDir d("render_map");
	CSparseMap emptyMap;
	TTrajectory path;
	for (int i = 0; i <= 100; i++)
		path.push_back(TStampedPose::fromPose(i, mrpt::poses::CPose3D(0.5 + 0.02 * i, 1.2, 1.0, 0, 0, 0)));
	auto scene = buildMapScene(emptyMap, path);
	auto cloud = mrpt::opengl::CPointCloudColoured::Create();
	cloud->setName("dense_cloud");
	cloud->setPointSize(3.0f);
	for (double x = 0; x <= 4; x += 0.02)
		for (double y = 0; y <= 3; y += 0.02)
			cloud->push_back(static_cast<float>(x), static_cast<float>(y), 0.f, 0.1f, 0.7f, 0.1f);
	cloud->push_back(40.f, 40.f, 5.f, 0.1f, 0.7f, 0.1f);
	cloud->push_back(-40.f, 45.f, 5.f, 0.1f, 0.7f, 0.1f);
	scene->insert(cloud);
	CSemanticOcTree tree(0.1);
	for (double x = 0.05; x < 4; x += 0.1)
		for (double y = 0.05; y < 3; y += 0.1)
			for (int k = 0; k < 4; k++)
				tree.updateNode(octomap::point3d(static_cast<float>(x), static_cast<float>(y), 0.05f), true)->label =
					57;  // c + 1: COCO chair
	const std::vector<std::string> names =
		readClassNames(std::string(YESSLAM_SOURCE_DIR) + "/share/mrpt_yesslam/models/yolo-fastest-1.1/coco.names");
	scene->insert(semanticOcTreeObject(tree, names));
	ASSERT_TRUE(scene->saveToFile(d / "map.3Dscene"));

	const cv::Vec3b label = labelColour(57);
	auto count = [](const cv::Mat& img, const std::function<bool(const cv::Vec3b&)>& is)
	{
		std::size_t n = 0;
		for (int y = 0; y < img.rows; y++)
			for (int x = 0; x < img.cols; x++) n += is(img.at<cv::Vec3b>(y, x));
		return n;
	};
	auto near = [](const cv::Vec3b& a, const cv::Vec3b& b, int tol)
	{ return std::abs(a[0] - b[0]) <= tol && std::abs(a[1] - b[1]) <= tol && std::abs(a[2] - b[2]) <= tol; };
	TRenderOptions o;
	o.width = 400;
	o.height = 300;
	for (const double elevation : {35.0, 90.0})
	{
		SCOPED_TRACE(elevation);
		o.elevationDeg = elevation;
		renderSceneFileToPng(d / "map.3Dscene", d / "default.png", o);
		const cv::Mat img = cv::imread(d / "default.png", cv::IMREAD_COLOR);
		const std::size_t green = count(img, [](const cv::Vec3b& p) { return p[1] > 120 && p[0] < 80 && p[2] < 80; });
		const std::size_t red = count(img, [](const cv::Vec3b& p) { return p[2] > 150 && p[1] < 90 && p[0] < 90; });
		EXPECT_GT(green, static_cast<std::size_t>(img.total() / 4))
			<< "the cloud fills the picture (stray points aside), voxels hidden";
		EXPECT_GT(red, 250u) << "the path is a visible line";
		cv::Mat grey, diff;
		cv::absdiff(img, cv::Scalar(255, 255, 255), diff);
		cv::cvtColor(diff, grey, cv::COLOR_BGR2GRAY);
		const cv::Rect r = cv::boundingRect(grey > 8);
		EXPECT_GT(std::max(static_cast<double>(r.width) / img.cols, static_cast<double>(r.height) / img.rows), 0.85)
			<< "framed to fill";
	}
	// The OctoMap shown: its legend (the label's swatch and name) in the top-left corner, from the
	// side and from straight above.
	o.hide = std::vector<std::string>{"dense_cloud", "map_points", "keyframe"};
	for (const double elevation : {10.0, 90.0})
	{
		SCOPED_TRACE(elevation);
		o.elevationDeg = elevation;
		renderSceneFileToPng(d / "map.3Dscene", d / "octomap.png", o);
		const cv::Mat img = cv::imread(d / "octomap.png", cv::IMREAD_COLOR);
		const cv::Mat corner = img(cv::Rect(0, 0, img.cols / 4, img.rows / 8));
		EXPECT_GT(count(corner, [&](const cv::Vec3b& p) { return near(p, label, 6); }), 20u) << "the legend's swatch";
		EXPECT_GT(count(corner, [&](const cv::Vec3b& p) { return p[0] < 80 && p[1] < 80 && p[2] < 80; }), 30u)
			<< "the legend's text";
	}
}

// Issue 43 item 9: a map's OctoMap voxels render in their colour from every side: walls seen from
// behind the light as well as floors, not nearly black (MRPT's 0.2 ambient light gave them a fifth
// of their colour).
TEST(Render, OctoMapWallsShowTheirColourFromEverySide)
{
	TempDir d("render_walls");
	CSemanticOcTree tree(0.1);
	// An L of walls (x-z and y-z planes) on a floor, all labelled "chair" (label 57).
	for (double a = 0.05; a < 3; a += 0.1)
		for (double b = 0.05; b < 2; b += 0.1)
			for (const auto& p :
				 {octomap::point3d(float(a), 0.05f, float(b)), octomap::point3d(0.05f, float(a), float(b)),
				  octomap::point3d(float(a), float(b), 0.05f)})
				for (int k = 0; k < 4; k++) tree.updateNode(p, true)->label = 57;
	CSparseMap emptyMap;
	auto scene = buildMapScene(emptyMap, {});
	scene->insert(semanticOcTreeObject(tree, {}));
	ASSERT_TRUE(scene->saveToFile(d / "walls.3Dscene"));
	const cv::Vec3b label = labelColour(57);
	const double labelBrightness = (label[0] + label[1] + label[2]) / 3.0;
	for (const double azimuth : {45.0, 225.0})  // the inside of the L, then its outside
	{
		TRenderOptions o;
		o.width = 400;
		o.height = 300;
		o.azimuthDeg = azimuth;
		renderSceneFileToPng(d / "walls.3Dscene", d / "walls.png", o);
		const cv::Mat img = cv::imread(d / "walls.png", cv::IMREAD_COLOR);
		ASSERT_FALSE(img.empty());
		std::vector<double> voxel;
		for (int y = 40; y < img.rows; y++)  // below the legend
			for (int x = 0; x < img.cols; x++)
			{
				const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
				if (p[0] > 245 && p[1] > 245 && p[2] > 245) continue;  // background
				voxel.push_back((p[0] + p[1] + p[2]) / 3.0);
			}
		ASSERT_GT(voxel.size(), img.total() / 10) << azimuth;
		std::sort(voxel.begin(), voxel.end());
		const double dark = voxel[voxel.size() / 10];  // the darkest tenth: the faces turned from the light
		EXPECT_GT(dark, 0.45 * labelBrightness)
			<< "azimuth " << azimuth << ": median " << voxel[voxel.size() / 2] << ", label " << labelBrightness;
	}
}
