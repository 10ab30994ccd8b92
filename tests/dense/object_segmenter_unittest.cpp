// CObjectSegmenter, the dense map's static-object labels: a desk with a monitor on it, in front of
// a wall, on a floor, rendered with yesslam-sim's ray caster and Kinect-like depth noise. The desk
// is what the paper's single-seed flood fill cannot label (its seed lands on the monitor, or on
// the wall seen between the legs); the segments inside the box can.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>

#include "mrpt_yesslam/dense/CDenseSemanticMapper.h"
#include "mrpt_yesslam/dense/CObjectSegmenter.h"
#include "mrpt_yesslam/sim/CBoxRaycaster.h"

using namespace mrpt_yesslam;

namespace
{
constexpr std::uint16_t kFloor = 1, kWall = 2, kDesk = 3, kMonitor = 4;

struct TScene
{
	mrpt::img::TCamera K;
	cv::Mat bgr, depth, instance;
	std::vector<TDetection> dets;  //!< desk (larger) first, then the monitor
};

TRayBox box(double x, double y, double z, double sx, double sy, double sz, std::uint16_t id)
{
	TRayBox b;
	b.pose = mrpt::poses::CPose3D(x, y, z, 0, 0, 0);
	b.sx = sx, b.sy = sy, b.sz = sz;
	b.id = id;
	return b;
}

// World in the camera's axes (x right, y down, z forward), the camera 1.3 m above the floor
// looking 25 degrees down at a desk 2.3 m away (top 0.72 m high, 1.4 x 0.7 m, four legs), a
// monitor standing on it, a wall 1.2 m behind the desk.
TScene deskScene()
{
	TScene s;
	s.K.ncols = 640, s.K.nrows = 480;
	s.K.fx(535.4), s.K.fy(539.2), s.K.cx(320.1), s.K.cy(247.6);
	s.K.dist.fill(0);
	const double floorY = 1.3, topY = floorY - 0.72;
	std::vector<TRayBox> w = {box(0, floorY + 0.05, 3, 10, 0.1, 10, kFloor), box(0, 0, 3.7, 10, 6, 0.1, kWall),
							  box(0, topY + 0.02, 2.5, 1.4, 0.04, 0.7, kDesk),
							  box(0, topY - 0.2, 2.6, 0.55, 0.36, 0.04, kMonitor)};
	for (int lx : {-1, 1})
		for (int lz : {-1, 1}) w.push_back(box(lx * 0.65, topY + 0.37, 2.5 + lz * 0.3, 0.05, 0.7, 0.05, kDesk));
	const CBoxRaycaster rc;
	rc.render(w, mrpt::poses::CPose3D(0, 0, 0, 0, 0, -25 * M_PI / 180), s.K, s.bgr, s.depth, s.instance);
	// Kinect-like noise as yesslam-sim's: sigma 1.425e-3 z^2, disparity quantised to 1/8 pixel.
	cv::RNG rng(7);
	const float fb = static_cast<float>(s.K.fx() * 0.075);
	for (int v = 0; v < s.depth.rows; v++)
		for (int u = 0; u < s.depth.cols; u++)
		{
			float& z = s.depth.at<float>(v, u);
			if (z <= 0) continue;
			z += static_cast<float>(1.425e-3 * z * z * rng.gaussian(1.0));
			z = fb / (std::nearbyint(fb / z * 8.0f) / 8.0f);
		}
	for (const std::uint16_t id : {kDesk, kMonitor})
	{
		TDetection d;
		d.classId = id == kDesk ? 60 : 62;
		d.score = 0.8f;
		d.box = cv::Rect2f(cv::boundingRect(s.instance == id));
		s.dets.push_back(d);
	}
	return s;
}

// Share of the pixels of `id` labelled `det` + 1, and share of the pixels labelled `det` + 1 that are `id`.
std::pair<double, double> recallPrecision(const TScene& s, const TObjectLabels& l, std::uint16_t id, int det)
{
	double truth = 0, hit = 0, labelled = 0;
	for (int v = 0; v < s.depth.rows; v++)
		for (int u = 0; u < s.depth.cols; u++)
		{
			const bool is = s.instance.at<std::uint16_t>(v, u) == id,
					   got = l.instance.at<std::uint16_t>(v, u) == det + 1;
			truth += is, hit += is && got, labelled += got;
		}
	return {hit / std::max(1.0, truth), labelled > 0 ? hit / labelled : 0.0};
}
}  // namespace

TEST(ObjectSegmenter, LabelsADeskAndTheMonitorOnItButNotTheFloorOrTheWallBetweenItsLegs)
{
	const TScene s = deskScene();
	ASSERT_GT(s.dets[0].box.area(), 4 * s.dets[1].box.area());
	const CObjectSegmenter seg{CObjectSegmenter::TParams()};
	const TObjectLabels l = seg.segment(s.depth, s.K, s.dets);
	const auto [deskRecall, deskPrecision] = recallPrecision(s, l, kDesk, 0);
	const auto [monRecall, monPrecision] = recallPrecision(s, l, kMonitor, 1);
	EXPECT_GT(deskRecall, 0.6);
	EXPECT_GT(deskPrecision, 0.9);
	EXPECT_GT(monRecall, 0.9);
	EXPECT_GT(monPrecision, 0.95);
	// The wall seen under the desk top and between the legs, and the floor, stay unlabelled.
	std::size_t wallInBox = 0, wallLabelled = 0, floorLabelled = 0;
	const cv::Rect deskBox(s.dets[0].box);
	for (int v = deskBox.y; v < deskBox.br().y; v++)
		for (int u = deskBox.x; u < deskBox.br().x; u++)
		{
			const auto id = s.instance.at<std::uint16_t>(v, u);
			const bool labelled = l.instance.at<std::uint16_t>(v, u) != 0;
			if (id == kWall) wallInBox++, wallLabelled += labelled;
			if (id == kFloor) floorLabelled += labelled;
		}
	ASSERT_GT(wallInBox, 1000u);
	EXPECT_LT(wallLabelled, wallInBox / 20);
	EXPECT_LT(floorLabelled, 200u);
	EXPECT_EQ(cv::countNonZero(l.unknown), 0);

	// The paper's fill, seeded at the box centre, finds the monitor or the wall, not the desk.
	CDenseSemanticMapper::TOptions fo;
	fo.labelMethod = "fill";
	const CDenseSemanticMapper fill(fo, CDynamicObjectMasker::TOptions(), 80);
	EXPECT_LT(recallPrecision(s, fill.labelPixels(s.depth, s.K, s.dets), kDesk, 0).first, 0.3);
}

TEST(ObjectSegmenter, ABoxOverPlainWallFindsNoObjectAndGivesNoEvidence)
{
	const TScene s = deskScene();
	TDetection clock;
	clock.classId = 74, clock.score = 0.6f, clock.box = cv::Rect2f(40, 10, 80, 60);  // wall only
	ASSERT_TRUE(cv::countNonZero(s.instance(cv::Rect(clock.box)) != kWall) == 0);
	const CObjectSegmenter seg{CObjectSegmenter::TParams()};
	const TObjectLabels l = seg.segment(s.depth, s.K, {clock});
	EXPECT_EQ(cv::countNonZero(l.instance), 0);
	EXPECT_EQ(cv::countNonZero(l.unknown(cv::Rect(clock.box))), 80 * 60);
	EXPECT_EQ(cv::countNonZero(l.unknown), 80 * 60);
}
