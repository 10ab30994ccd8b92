// Geometric loop verification on real revisits: the real Bonn crowd slice (Bonn RGB-D Dynamic
// Dataset, Palazzolo et al., IROS 2019; research data used for testing only, never copied: see
// ../shared/data/bonn_crowd_dev/SOURCE.md).
#include <gtest/gtest.h>
#include <mrpt/poses/Lie/SO.h>

#include <algorithm>
#include <set>

#include "TestUtils.h"
#include "mrpt_yesslam/eval/GroundTruthFormat.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/feature/RollingShutter.h"
#include "mrpt_yesslam/geometry/RelativeMotion.h"
#include "mrpt_yesslam/system/CYesSlamSystem.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

// Issue 40 item 1: frame 0 and frames 150-205 of the slice see the same place 3-12 cm and 4-14
// degrees apart (ground truth), the later ones with people walking close. Keyframes made at those
// frames (default detector and masks, as a run makes them) are verified as a loop pair. Before
// (matching in the direct index, the relative pose from the 3D-3D fit) two of the seven were
// accepted, 6 and 11 cm off the ground truth's relative pose. Then (every static keypoint with
// depth matched, guided matching after the RANSAC seed, the pose refined on reprojection) the four
// from frame 180 on were accepted 2.6-3.8 cm off; then, with the pose solved again on the place's
// points the projection search finds, 1.1-2.7 cm off.
// The rest was the rolling shutter: a run's keyframes have their keypoints moved to the middle
// row's moment along the motion model's velocity (CYesSlamSystem, feature/RollingShutter.h), and
// this test's did not. Undone as a run undoes it (the mean motion of the last tenth of a second,
// here the ground truth's), the four pairs are 0.7-1.8 cm off (without: 1.1 / 1.1 / 2.7 / 1.8),
// every one within the 2 cm and 2 degrees.
// Frames 150-170 keep 5-22 consistent correspondences among the 100-300 static keypoints with
// depth the people leave, too few for ORB-SLAM2's thresholds (20 inliers, 40 projection matches)
// (docs/benchmarks.md, "Loops on real frames"). Those figures were measured with the geometric
// check's box part on; the frames are built as a mapping run builds them since 2026-11-29
// ([GeometricCheck] boxes = auto: off when mapping), and the same bounds hold.
TEST(LoopClosing, RealRevisitsOfTheBonnSliceVerifyWithTheirTrueRelativePose)
{
	const std::string dir = sharedFile("data/bonn_crowd_dev");
	TYesSlamOptions o;
	const TTrajectory gt = readGroundTruth(dir + "/groundtruth.txt", EGroundTruthFormat::Bonn);
	const auto gtAt = [&](double t) -> std::optional<mrpt::poses::CPose3D>
	{
		const auto it = std::min_element(gt.begin(), gt.end(), [&](const TStampedPose& a, const TStampedPose& b) { return std::abs(a.t - t) < std::abs(b.t - t); });
		if (it == gt.end() || std::abs(it->t - t) > 0.02) return std::nullopt;
		return it->asPose();
	};
	CFrameBuilder builder(createObjectDetector(o.detector), o.masker, o.orb, true, false, o.geometric);
	const auto vocabulary = std::make_shared<CVocabulary>(CVocabulary::load(CVocabulary::shippedPath()));
	auto database = std::make_shared<CBowDatabase>(vocabulary->numWords());
	CSparseMap map;
	CLoopDetector detector(o.loop.detection, map, vocabulary, database, o.keyFrames.semantic, o.orb.scaleFactor, o.tracking.maxDepth);
	auto src = openInputSource(dir, o.input);
	const std::set<std::size_t> wanted{0, 150, 160, 170, 180, 190, 200, 205};
	std::map<std::size_t, TKeyFrameId> kfOf;
	std::map<std::size_t, mrpt::poses::CPose3D> truth;
	std::size_t index = 0;
	while (auto obs = src->next())
	{
		if (wanted.count(index))
		{
			cv::Mat bgr = obs->intensityImage.asCvMatRef();
			auto f = builder.build(bgr, depthInMetres(*obs), observationTime(*obs), obs->cameraParamsIntensity, index);
			const auto pose = gtAt(f->timestamp);
			ASSERT_TRUE(pose.has_value()) << "frame " << index;
			// The shutter undone along the motion of the last 0.1 s, as the motion model's mean of
			// the last three tracked steps gives it in a run (CTracker::motionOver).
			const auto before = gtAt(f->timestamp - 0.1);
			ASSERT_TRUE(before.has_value()) << "frame " << index;
			unrollShutter(f->features, CPinholeCamera(f->camera), scaleMotion((-*before) + *pose, kConsumerRgbdReadout / 0.1));
			f->pose = *pose;
			f->tracked = true;
			truth[index] = *pose;
			const TKeyFrameId kf = map.addKeyFrame(f, o.tracking.maxDepth);
			map.setKeyFrameBow(kf, vocabulary->bowOf(*map.keyFrame(kf).features, o.loop.detection.directLevel));
			kfOf[index] = kf;
		}
		if (++index > *wanted.rbegin()) break;
	}
	ASSERT_EQ(kfOf.size(), wanted.size());
	std::size_t accepted = 0;
	for (const std::size_t k : wanted)
	{
		if (k == 0) continue;
		const auto loop = detector.verify(kfOf.at(k), kfOf.at(0));
		const mrpt::poses::CPose3D trueRel = (-truth.at(0)) + truth.at(k);
		if (!loop)
		{
			EXPECT_LT(k, 180u) << "frame " << k << " refused (true relative pose " << trueRel << ")";
			continue;
		}
		accepted++;
		const mrpt::poses::CPose3D err = (-trueRel) + loop->relative;
		const double deg = mrpt::RAD2DEG(mrpt::poses::Lie::SO<3>::log(err.getRotationMatrix()).norm());
		EXPECT_LT(err.norm(), 0.02) << "frame " << k << ": " << loop->ransacInliers << " inliers, true " << trueRel << " found " << loop->relative;
		EXPECT_LT(deg, 1.0) << "frame " << k;
	}
	EXPECT_GE(accepted, 4u);
}
