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
namespace
{
// Keyframes at the given frames of the real Bonn slice, made as a run makes them (default
// detector and masks, the rolling shutter undone) at their ground-truth poses, with their words,
// and a loop detector over them.
struct TBonnRevisits
{
	TYesSlamOptions o;
	std::shared_ptr<CVocabulary> vocabulary;
	std::shared_ptr<CBowDatabase> database;
	CSparseMap map;
	std::unique_ptr<CLoopDetector> detector;
	std::map<std::size_t, TKeyFrameId> kfOf;
	std::map<std::size_t, mrpt::poses::CPose3D> truth;

	explicit TBonnRevisits(const std::set<std::size_t>& wanted) { make(wanted); }
	void make(const std::set<std::size_t>& wanted)
	{
		const std::string dir = sharedFile("data/bonn_crowd_dev");
		const TTrajectory gt = readGroundTruth(dir + "/groundtruth.txt", EGroundTruthFormat::Bonn);
		const auto gtAt = [&](double t) -> std::optional<mrpt::poses::CPose3D>
		{
			const auto it = std::min_element(gt.begin(), gt.end(),
											 [&](const TStampedPose& a, const TStampedPose& b)
											 { return std::abs(a.t - t) < std::abs(b.t - t); });
			if (it == gt.end() || std::abs(it->t - t) > 0.02) return std::nullopt;
			return it->asPose();
		};
		CFrameBuilder builder(createObjectDetector(o.detector), o.masker, o.orb, true, false, o.geometric);
		vocabulary = std::make_shared<CVocabulary>(CVocabulary::load(CVocabulary::shippedPath()));
		database = std::make_shared<CBowDatabase>(vocabulary->numWords());
		detector = std::make_unique<CLoopDetector>(o.loop.detection, map, vocabulary, database, o.keyFrames.semantic,
												   o.orb.scaleFactor, o.tracking.maxDepth);
		auto src = openInputSource(dir, o.input);
		std::size_t index = 0;
		while (auto obs = src->next())
		{
			if (wanted.count(index))
			{
				cv::Mat bgr = obs->intensityImage.asCvMatRef();
				auto f =
					builder.build(bgr, depthInMetres(*obs), observationTime(*obs), obs->cameraParamsIntensity, index);
				const auto pose = gtAt(f->timestamp);
				ASSERT_TRUE(pose.has_value()) << "frame " << index;
				// The shutter undone along the motion of the last 0.1 s, as the motion model's mean
				// of the last three tracked steps gives it in a run (CTracker::motionOver).
				const auto before = gtAt(f->timestamp - 0.1);
				ASSERT_TRUE(before.has_value()) << "frame " << index;
				unrollShutter(f->features, CPinholeCamera(f->camera),
							  scaleMotion((-*before) + *pose, kConsumerRgbdReadout / 0.1));
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
	}
	/** How far `relative` (keyframe at `k` in the one at `ref`) is from the ground truth's: metres, degrees. */
	std::pair<double, double> error(std::size_t ref, std::size_t k, const mrpt::poses::CPose3D& relative) const
	{
		const mrpt::poses::CPose3D err = (-((-truth.at(ref)) + truth.at(k))) + relative;
		return {err.norm(), mrpt::RAD2DEG(mrpt::poses::Lie::SO<3>::log(err.getRotationMatrix()).norm())};
	}
};
}  // namespace

TEST(LoopClosing, RealRevisitsOfTheBonnSliceVerifyWithTheirTrueRelativePose)
{
	const std::set<std::size_t> wanted{0, 150, 160, 170, 180, 190, 200, 205};
	const TBonnRevisits r(wanted);
	ASSERT_EQ(r.kfOf.size(), wanted.size());
	std::size_t accepted = 0;
	for (const std::size_t k : wanted)
	{
		if (k == 0) continue;
		const auto loop = r.detector->verify(r.kfOf.at(k), r.kfOf.at(0));
		if (!loop)
		{
			EXPECT_LT(k, 180u) << "frame " << k << " refused";
			continue;
		}
		accepted++;
		const auto [metres, deg] = r.error(0, k, loop->relative);
		EXPECT_LT(metres, 0.02) << "frame " << k << ": " << loop->ransacInliers << " inliers, found " << loop->relative;
		EXPECT_LT(deg, 1.0) << "frame " << k;
	}
	EXPECT_GE(accepted, 4u);
}

// Detection runs beside local mapping and the global BA: the place can move while a pair is
// verified. Here the whole map moves rigidly (10 cm, 6 degrees) after the pair's measurements were
// fitted and before the place's points are read. The relative pose between the two keyframes is the
// same in either map, and so must the loop's be; before, the place's pose was the one read at the
// start and its points the moved ones, and the loop carried the whole move.
TEST(LoopClosing, APairVerifiedWhileTheMapMovesKeepsItsTrueRelativePose)
{
	TBonnRevisits r({0, 200});
	ASSERT_EQ(r.kfOf.size(), 2u);
	bool moved = false;
	r.detector->setVerifyHook(
		[&]
		{
			if (moved) return;
			moved = true;
			const mrpt::poses::CPose3D T(0.10, -0.05, 0.03, mrpt::DEG2RAD(5.0), mrpt::DEG2RAD(-3.0),
										 mrpt::DEG2RAD(2.0));
			std::map<TKeyFrameId, mrpt::poses::CPose3D> corrected;
			for (const auto& k : r.map.keyFramePoses()) corrected[k.id] = T + k.pose;
			r.map.applyCorrection(corrected);
		});
	const auto loop = r.detector->verify(r.kfOf.at(200), r.kfOf.at(0));
	ASSERT_TRUE(moved);
	ASSERT_TRUE(loop.has_value());
	const auto [metres, deg] = r.error(0, 200, loop->relative);
	EXPECT_LT(metres, 0.02);
	EXPECT_LT(deg, 1.0);
}
