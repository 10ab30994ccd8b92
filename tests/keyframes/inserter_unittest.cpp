// The keyframe decision: the ORB-SLAM2 rules, the semantic policy's safety net, option checks.
#include <gtest/gtest.h>

#include "TestUtils.h"
#include "mrpt_yesslam/keyframes/CKeyFrameInserter.h"

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
	auto first = ins.addFrame(tracked(0, 400), ref, 0);	// the first frame is the selector's first reference
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
