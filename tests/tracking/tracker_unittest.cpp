// Tracking on real sensor data: the 9 consecutive TUM fr1_desk frames in ../shared (Kinect depth,
// motion-capture ground truth; CC BY 4.0, see its SOURCE.md), and recovery after a frame with
// nothing to track.
#include <gtest/gtest.h>

#include "TestUtils.h"
#include "mrpt_yesslam/eval/TrajectoryEvaluator.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/system/CYesSlamSystem.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

namespace
{
TYesSlamOptions realOptions()
{
	TYesSlamOptions o;
	o.detector.backend = "none";
	o.system.parallel = false;
	o.input.camera = "fr1";
	return o;
}
}  // namespace

TEST(Tracker, RealFr1DeskFramesMatchMotionCapture)
{
	const std::string dir = sharedFile("data/tum_fr1_desk_9frames");
	const TTrajectory gt = readTumTrajectory(sharedFile("data/tum_fr1_desk_9frames/groundtruth.txt"));
	const TYesSlamOptions o = realOptions();
	CYesSlamSystem sys(o);
	auto src = openInputSource(dir, o.input);
	std::size_t n = 0;
	while (auto obs = src->next())
	{
		const TFrameReport r = sys.processFrame(*obs);
		EXPECT_TRUE(r.tracked) << "frame " << n;
		if (n > 0) { EXPECT_GT(r.inliers, 100u) << "frame " << n; }
		n++;
	}
	ASSERT_EQ(n, 9u);
	const TAteResult ate = computeAte(gt, sys.trajectory(), TEvalOptions());
	EXPECT_EQ(ate.stats.n, 9u);
	// fr1_desk moves ~0.4 m/s: 9 frames span ~10 cm; the mocap itself is good to a few mm.
	EXPECT_LT(ate.stats.rmse, 0.01);
}

TEST(Tracker, RecoversAfterAFrameWithoutFeatures)
{
	const std::string dir = sharedFile("data/tum_fr1_desk_9frames");
	const TYesSlamOptions o = realOptions();
	CYesSlamSystem sys(o);
	auto src = openInputSource(dir, o.input);
	std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> frames;
	while (auto obs = src->next()) frames.push_back(obs);
	ASSERT_EQ(frames.size(), 9u);
	for (int i = 0; i < 4; i++) EXPECT_TRUE(sys.processFrame(*frames[static_cast<std::size_t>(i)]).tracked);
	// A black frame with no depth (a covered lens): no crash, not tracked, a pose all the same.
	const cv::Mat black(480, 640, CV_8UC3, cv::Scalar::all(0)), noDepth(480, 640, CV_32F, cv::Scalar(0));
	const TFrameReport lost = sys.processFrame(black, noDepth, observationTime(*frames[4]) - 0.001, frames[4]->cameraParamsIntensity);
	EXPECT_FALSE(lost.tracked);
	for (std::size_t i = 4; i < 9; i++) EXPECT_TRUE(sys.processFrame(*frames[i]).tracked) << i;
	EXPECT_EQ(sys.trajectory().size(), 10u);
	EXPECT_EQ(sys.stats().lostFrames, 1u);
}

// A person filling the whole image (a detection box over every pixel): every feature is masked, the
// frame cannot be tracked, and the system goes on with the motion model; the held box (holdFrames)
// masks the next frame too; then tracking resumes on the real frames.
TEST(Tracker, KeepsGoingWhenAPersonCoversTheWholeImage)
{
	const std::string dir = sharedFile("data/tum_fr1_desk_9frames");
	const TTrajectory gt = readTumTrajectory(sharedFile("data/tum_fr1_desk_9frames/groundtruth.txt"));
	TYesSlamOptions o = realOptions();
	auto src = openInputSource(dir, o.input);
	std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> frames;
	while (auto obs = src->next()) frames.push_back(obs);
	ASSERT_EQ(frames.size(), 9u);
	TempDir d("cover");
	char line[128];
	std::snprintf(line, sizeof(line), "%.6f 0 0.95 0 0 640 480\n", observationTime(*frames[4]));
	writeText(d / "detections.txt", std::string("# timestamp class_id score x y w h\n") + line);
	o.detector.backend = "file";
	o.detector.file = d / "detections.txt";
	o.masker.holdFrames = 1;
	o.masker.method = "box";  // the whole image is masked (a fill would keep what lies behind the seed's depth)
	CYesSlamSystem sys(o);
	for (std::size_t i = 0; i < 9; i++)
	{
		const TFrameReport r = sys.processFrame(*frames[i]);
		if (i == 4 || i == 5)
			EXPECT_FALSE(r.tracked) << "frame " << i << " has no static feature";
		else
			EXPECT_TRUE(r.tracked) << "frame " << i;
	}
	EXPECT_EQ(sys.trajectory().size(), 9u);
	EXPECT_EQ(sys.stats().lostFrames, 2u);
	// The two blind frames got the constant-velocity pose: the whole run stays within a few cm.
	EXPECT_LT(computeAte(gt, sys.trajectory(), TEvalOptions()).stats.rmse, 0.03);
}

// Issue 14 (blinded camera): frames with no usable view are lost, and their poses continue the
// last measured motion, damped, instead of stopping dead while the camera moves on (fr1_desk moves
// about 0.4 m/s: two held frames are a centimetre or more off).
TEST(Tracker, LostFramesContinueTheLastMotion)
{
	const std::string dir = sharedFile("data/tum_fr1_desk_9frames");
	const TTrajectory gt = readTumTrajectory(sharedFile("data/tum_fr1_desk_9frames/groundtruth.txt"));
	auto src = openInputSource(dir, realOptions().input);
	std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> frames;
	while (auto obs = src->next()) frames.push_back(obs);
	ASSERT_EQ(frames.size(), 9u);
	const cv::Mat black(480, 640, CV_8UC3, cv::Scalar::all(0)), noDepth(480, 640, CV_32F, cv::Scalar(0));
	const auto worstError = [&](double damping)
	{
		TYesSlamOptions o = realOptions();
		o.tracking.lostDamping = damping;
		CYesSlamSystem sys(o);
		for (std::size_t i = 0; i < frames.size(); i++)
			if (i == 4 || i == 5)
				EXPECT_FALSE(sys.processFrame(black, noDepth, observationTime(*frames[i]), frames[i]->cameraParamsIntensity).tracked);
			else
				EXPECT_TRUE(sys.processFrame(*frames[i]).tracked) << i;
		EXPECT_EQ(sys.stats().lostFrames, 2u);
		return computeAte(gt, sys.trajectory(), TEvalOptions()).stats.max;
	};
	const double coasting = worstError(0.9), held = worstError(0.0);
	EXPECT_GT(held, 0.008);
	EXPECT_LT(coasting, 0.6 * held);
}
