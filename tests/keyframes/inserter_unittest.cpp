// The keyframe decision: the ORB-SLAM2 rules, the semantic policy's safety net, option checks.
#include <gtest/gtest.h>

#include "TestUtils.h"
#include "mrpt_yesslam/keyframes/CKeyFrameInserter.h"
#include "mrpt_yesslam/keyframes/CRecentFrames.h"

#include <random>

using namespace mrpt_yesslam;
using namespace yesslam_test;

namespace
{
TFrame tracked(std::size_t id, std::size_t inliers)
{
	TFrame f;
	f.id = id;
	f.tracked = true;
	f.numInliers = inliers;
	f.camera.ncols = 640;
	f.camera.nrows = 480;
	// 500 static keypoints without depth: enough static features, none "close".
	f.features.keypoints.resize(500);
	f.features.dynamic.assign(500, false);
	f.features.depth.assign(500, 0.f);
	f.mapPoints.assign(500, -1);
	return f;
}
}  // namespace

TEST(KeyFrameInserter, OrbSlamPolicyFollowsTheReferenceRatio)
{
	CKeyFrameInserter::TOptions o;
	o.policy = "orbslam";
	o.orbMinFrames = 5;
	o.orbMaxFrames = 30;
	CKeyFrameInserter ins(o);
	ins.keyFrameInserted(0);
	const CKeyFrameInserter::TReference ref{0, 400};
	// Plenty of the reference's points tracked: no keyframe.
	EXPECT_FALSE(ins.addFrame(tracked(1, 380), ref, 0));
	// Below 75% but before minFrames and above 25%: not yet (c1a, c1b, c1c all false).
	EXPECT_FALSE(ins.addFrame(tracked(2, 250), ref, 0));
	// After minFrames: yes.
	EXPECT_TRUE(ins.addFrame(tracked(6, 250), ref, 0));
	// Below 25% (c1c) at once, even before minFrames.
	ins.keyFrameInserted(6);
	EXPECT_TRUE(ins.addFrame(tracked(7, 90), ref, 0));
	// Too few inliers (<= 15) never make a keyframe; an untracked frame neither.
	EXPECT_FALSE(ins.addFrame(tracked(8, 12), ref, 0));
	TFrame lost = tracked(9, 300);
	lost.tracked = false;
	EXPECT_FALSE(ins.addFrame(lost, ref, 0));
}

TEST(KeyFrameInserter, SemanticPolicyDecidesPerIntervalAndForcesWhenTheMapIsLeft)
{
	CKeyFrameInserter::TOptions o;
	CKeyFrameInserter ins(o);
	const CKeyFrameInserter::TReference ref{0, 400};
	auto first = ins.addFrame(tracked(0, 400), ref, 0);  // the first frame is the selector's first reference
	ASSERT_TRUE(first);
	EXPECT_EQ(first->frameId, 0u);
	// Frames with motion in (D_min, D_max) and enough inliers: one decision per interval of 5.
	std::size_t decisions = 0;
	for (std::size_t i = 1; i <= 10; i++)
		if (auto d = ins.addFrame(tracked(i, 300), ref, 0.05))
		{
			decisions++;
			EXPECT_FALSE(d->forced);
			EXPECT_LE(d->frameId, i);
		}
	EXPECT_EQ(decisions, 2u);
	// Inliers below 25% of the reference's points: a forced keyframe at this very frame.
	const auto forced = ins.addFrame(tracked(11, 60), ref, 0.05);
	ASSERT_TRUE(forced);
	EXPECT_TRUE(forced->forced);
	EXPECT_EQ(forced->frameId, 11u);
}

TEST(KeyFrameInserter, RejectsInvalidOptions)
{
	CKeyFrameInserter::TOptions o;
	o.policy = "every";
	expectInputError([&] { CKeyFrameInserter x(o); }, {"policy", "every"});
	o.policy = "orbslam";
	o.orbMaxFrames = 0;
	expectInputError([&] { CKeyFrameInserter x(o); }, {"orbMaxFrames"});
}

// Review finding: a forced keyframe inside an interval did not restart Algorithm 1, which could then
// close the interval by naming a frame from before the forced one: keyframe ids out of time order.
TEST(KeyFrameInserter, ForcedKeyFrameRestartsTheSemanticInterval)
{
	CKeyFrameInserter::TOptions o;
	o.policy = "semantic";
	o.semantic.interval = 5;
	CKeyFrameInserter ins(o);
	const CKeyFrameInserter::TReference ref{0, 400};
	// The first frame is the selector's first reference.
	ASSERT_TRUE(ins.addFrame(tracked(0, 400), ref, 0));
	std::vector<std::size_t> chosen;
	// Frames 1-3 of an interval with enough motion (each a candidate), then frame 4 loses most of
	// the reference's points: forced. Frames 5-12 follow with motion.
	for (std::size_t id = 1; id <= 12; id++)
	{
		const std::size_t inliers = id == 4 ? 60 : 350;
		TFrame f = tracked(id, inliers);
		// A person in a different place in each frame, so that every frame differs from the reference.
		TDetection d;
		d.classId = 0;
		d.score = 0.9f;
		d.box = {static_cast<float>(40 * id), 100, 80, 200};
		f.detections.push_back(d);
		if (const auto dec = ins.addFrame(f, ref, 0.05))
		{
			if (dec->forced)
			{
				EXPECT_EQ(dec->frameId, 4u);
			}
			chosen.push_back(dec->frameId);
			ins.keyFrameInserted(dec->frameId);
		}
	}
	ASSERT_GE(chosen.size(), 2u);
	EXPECT_EQ(chosen[0], 4u);
	for (std::size_t i = 1; i < chosen.size(); i++)
		EXPECT_GT(chosen[i], chosen[i - 1]) << "keyframes out of time order";
}

// Beyond the paper (ORB-SLAM2's c2): Algorithm 1 chooses a frame every interval wherever the camera
// is; the choice becomes a keyframe only if that frame sees more than the map already holds.
TEST(KeyFrameInserter, SemanticChoiceCoveredByTheMapIsNotInserted)
{
	const CKeyFrameInserter::TReference ref{0, 400};
	const auto decisions = [&](double refRatio, std::size_t inliers)
	{
		CKeyFrameInserter::TOptions o;
		o.semanticRefRatio = refRatio;
		CKeyFrameInserter ins(o);
		EXPECT_TRUE(ins.addFrame(tracked(0, 400), ref, 0));  // the first reference is never judged
		std::size_t n = 0;
		for (std::size_t i = 1; i <= 20; i++) n += ins.addFrame(tracked(i, inliers), ref, 0.05).has_value();
		EXPECT_EQ(ins.redundantChoices(), 4 - n);
		return n;
	};
	EXPECT_EQ(decisions(0.9, 300), 4u);  // 75 % of the reference's points: new content, one per interval
	EXPECT_EQ(decisions(0.9, 380), 0u);  // 95 %: the map covers the view
	EXPECT_EQ(decisions(1.0, 380), 4u);  // the check off: the paper's Algorithm 1 alone
}

TEST(RecentFrames, AChosenFrameComesAtItsPoseInTheMapAsItIsNow)
{
	// The frames Algorithm 1 may still choose: the last `capacity`, the tracked ones only, each
	// placed through its reference keyframe's current pose (issue 28 item 1).
	std::mt19937 rng(1);
	std::vector<mrpt::math::TPoint3D> world;
	for (int i = 0; i < 30; i++) world.emplace_back(0.05 * i - 0.7, 0.02 * i - 0.3, 2.0 + 0.03 * i);
	CSparseMap map;
	const TKeyFrameId kf =
		map.addKeyFrame(observeWorld(0, mrpt::poses::CPose3D(), world, std::vector<TPointId>(30, -1), rng), 10.0);
	CRecentFrames recent(2);
	for (std::size_t id = 1; id <= 3; id++)
	{
		auto f = std::make_shared<TFrame>();
		f->id = id;
		f->tracked = id != 2;
		f->pose = mrpt::poses::CPose3D(0.01 * static_cast<double>(id), 0, 0, 0, 0, 0);
		TAnchor a;
		a.refKf = kf;
		a.relative = f->pose;  // keyframe 0 is at the origin
		recent.push(f, a);
	}
	EXPECT_EQ(recent.tracked(1, map), nullptr) << "pushed out (capacity 2)";
	EXPECT_EQ(recent.tracked(2, map), nullptr) << "lost frames are never keyframes";
	const auto same = recent.tracked(3, map);
	ASSERT_NE(same, nullptr);
	EXPECT_NEAR(same->pose.x(), 0.03, 1e-12);
	// The map moves under it: the frame comes where the map is now.
	map.applyCorrection({{kf, mrpt::poses::CPose3D(1, 2, 3, 0.5, 0, 0)}});
	const auto moved = recent.tracked(3, map);
	ASSERT_NE(moved, nullptr);
	const mrpt::poses::CPose3D want =
		mrpt::poses::CPose3D(1, 2, 3, 0.5, 0, 0) + mrpt::poses::CPose3D(0.03, 0, 0, 0, 0, 0);
	EXPECT_LT((moved->pose.asVectorVal() - want.asVectorVal()).norm(), 1e-9);
	EXPECT_NE(moved.get(), same.get()) << "a copy: the tracked frame itself is left as it was";
}
