// The keyframe selection equations (paper eq. 8-17) on hand-built inputs, and Algorithm 1's
// interval logic on scripted frame sequences.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "TestUtils.h"
#include "mrpt_yesslam/keyframes/CSemanticKeyFrameSelector.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;

namespace
{
TDetection det(int cls, float x, float y, float w, float h)
{
	TDetection d;
	d.classId = cls;
	d.score = 0.9f;
	d.box = cv::Rect2f(x, y, w, h);
	return d;
}
const cv::Size kImg(640, 480);
}  // namespace

TEST(KeyFrameEquations, RegionVectorsAndJaccardEq9)
{
	// A person across the two left regions, a chair bottom-right, a screen top-right.
	const std::vector<TDetection> a = {det(0, 100, 50, 100, 400), det(56, 400, 300, 100, 100),
									   det(62, 400, 50, 100, 100)};
	const auto va = semanticRegionVectors(a, kImg, 2, 2);
	ASSERT_EQ(va.size(), 4u);
	EXPECT_EQ(va[0], (std::set<int>{0}));
	EXPECT_EQ(va[1], (std::set<int>{62}));
	EXPECT_EQ(va[2], (std::set<int>{0}));
	EXPECT_EQ(va[3], (std::set<int>{56}));
	// The person moved to the right half: region 0 and 2 lose it, regions 1 and 3 gain it.
	const std::vector<TDetection> b = {det(0, 420, 50, 100, 400), det(56, 400, 300, 100, 100),
									   det(62, 400, 50, 100, 100)};
	const auto vb = semanticRegionVectors(b, kImg, 2, 2);
	// Regions: {0} vs {} -> 0; {62} vs {62,0} -> 1/2; {0} vs {} -> 0; {56} vs {56,0} -> 1/2.
	EXPECT_DOUBLE_EQ(jaccardSimilarity(va, vb), (0 + 0.5 + 0 + 0.5) / 4);
	EXPECT_DOUBLE_EQ(jaccardSimilarity(va, va), 1.0);
	EXPECT_DOUBLE_EQ(jaccardSimilarity(semanticRegionVectors({}, kImg, 2, 2), semanticRegionVectors({}, kImg, 2, 2)),
					 1.0);
}

TEST(KeyFrameEquations, AreaSimilarityEq8)
{
	const std::vector<TDetection> a = {det(0, 0, 0, 100, 100)};
	EXPECT_DOUBLE_EQ(areaSimilarity(a, a, true), 0.5) << "as written, identical boxes give 0.5";
	EXPECT_DOUBLE_EQ(areaSimilarity(a, a, false), 1.0);
	const std::vector<TDetection> half = {det(0, 50, 0, 100, 100)};
	EXPECT_DOUBLE_EQ(areaSimilarity(a, half, true), 5000.0 / 20000.0);
	EXPECT_DOUBLE_EQ(areaSimilarity(a, {det(1, 0, 0, 100, 100)}, false), 0.0) << "different classes do not correspond";
	EXPECT_DOUBLE_EQ(areaSimilarity({}, {}, false), 1.0);
	EXPECT_DOUBLE_EQ(areaSimilarity(a, {}, false), 0.0);
	// Each box corresponds to at most one: two cur boxes over one ref box count once.
	EXPECT_DOUBLE_EQ(areaSimilarity({det(0, 0, 0, 100, 100), det(0, 0, 0, 100, 100)}, a, true), 10000.0 / 30000.0);
}

TEST(KeyFrameEquations, GlobalSimilarityEq10)
{
	EXPECT_DOUBLE_EQ(globalSimilarity(0.8, 0.4, 0.5), 0.6);
	EXPECT_DOUBLE_EQ(globalSimilarity(0.8, 0.4, 1.0), 0.8);
	EXPECT_DOUBLE_EQ(globalSimilarity(0.8, 0.4, 0.0), 0.4);
}

TEST(KeyFrameEquations, RigidMotionEq12to15AndAmplitudeEq16)
{
	const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
	const Eigen::Vector3d t(0.1, -0.05, 0.2);
	std::vector<Eigen::Vector3d> ref, cur;
	for (int i = 0; i < 30; i++)
	{
		const Eigen::Vector3d p(std::sin(i * 1.3), std::cos(i * 0.7) * 2, 1.0 + 0.1 * i);
		ref.push_back(p);
		cur.push_back(R * p + t);
	}
	Eigen::Matrix3d Re;
	Eigen::Vector3d te;
	ASSERT_TRUE(rigidMotionFromPoints(cur, ref, Re, te));
	EXPECT_LT((Re - R).norm(), 1e-9);
	EXPECT_LT((te - t).norm(), 1e-9);
	EXPECT_NEAR(motionAmplitude(Re, te), t.norm() + 0.3, 1e-9);
	// Angles near pi count as near pi, never more.
	EXPECT_NEAR(
		motionAmplitude(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix(), Eigen::Vector3d::Zero()),
		M_PI, 1e-9);
	// Collinear points do not fix a rotation.
	std::vector<Eigen::Vector3d> line = {{0, 0, 1}, {0, 0, 2}, {0, 0, 3}};
	EXPECT_FALSE(rigidMotionFromPoints(line, line, Re, te));
	EXPECT_FALSE(rigidMotionFromPoints({{0, 0, 1}}, {{0, 0, 1}}, Re, te));
}

namespace
{
// A frame whose single person box is shifted by `shift` pixels: the larger the shift, the lower S_G.
TKeyFrameInput frame(std::size_t id, float shift, double motion = 0.05, std::size_t inliers = 100,
					 std::size_t statics = 800)
{
	TKeyFrameInput f;
	f.frameId = id;
	f.imageSize = kImg;
	f.detections = {det(0, 100 + shift, 100, 150, 300), det(62, 400, 50, 100, 100)};
	f.numFeatures = 1000;
	f.numStatic = statics;
	f.numInliers = inliers;
	f.motion = motion;
	return f;
}
}  // namespace

TEST(KeyFrameSelector, PicksTheLeastSimilarFrameOfEachInterval)
{
	CSemanticKeyFrameSelector sel;
	auto first = sel.addFrame(frame(0, 0));
	ASSERT_TRUE(first);
	EXPECT_EQ(first->frameId, 0u);
	// Interval of 5: frame 3 differs most from the reference.
	const float shifts[5] = {10, 20, 200, 40, 30};
	std::optional<CSemanticKeyFrameSelector::TDecision> d;
	for (int k = 0; k < 5; k++)
	{
		d = sel.addFrame(frame(1 + k, shifts[k]));
		if (k < 4)
		{
			EXPECT_FALSE(d) << "decided before the interval closed";
		}
	}
	ASSERT_TRUE(d);
	EXPECT_EQ(d->frameId, 3u);
	EXPECT_LT(d->similarity, 0.9) << "the chosen frame must differ from the old reference";
	EXPECT_EQ(sel.referenceId(), 3u);
}

TEST(KeyFrameSelector, SkipsDynamicFramesAndWeakCandidates)
{
	CSemanticKeyFrameSelector sel;
	ASSERT_TRUE(sel.addFrame(frame(0, 0)));
	// A frame where people hide most features (N_sp <= 0.5 N_p) is not part of the interval, even if
	// it is the least similar: six frames are needed to close the interval of five.
	EXPECT_FALSE(sel.addFrame(frame(1, 300, 0.05, 100, 400)));
	for (int k = 2; k <= 5; k++) EXPECT_FALSE(sel.addFrame(frame(k, 10.f * k)));
	auto d = sel.addFrame(frame(6, 20));
	ASSERT_TRUE(d);
	EXPECT_EQ(d->frameId, 5u);
	// A candidate with too few inliers (N_in <= 20) becomes the reference but not a keyframe.
	for (int k = 7; k <= 10; k++) EXPECT_FALSE(sel.addFrame(frame(k, 5)));
	EXPECT_FALSE(sel.addFrame(frame(11, 250, 0.05, 15)));
	EXPECT_EQ(sel.referenceId(), 11u);
}

TEST(KeyFrameSelector, ExcessiveMotionShortensTheInterval)
{
	CSemanticKeyFrameSelector sel;
	ASSERT_TRUE(sel.addFrame(frame(0, 0)));
	EXPECT_EQ(sel.currentInterval(), 5);
	// Three consecutive frames with D >= D_max.
	for (int k = 1; k <= 3; k++) sel.addFrame(frame(k, 10.f * k, 0.5));
	EXPECT_EQ(sel.currentInterval(), 3);
	sel.addFrame(frame(4, 40, 0.5));
	auto d = sel.addFrame(frame(5, 50, 0.5));  // closes the first interval (5 frames)
	ASSERT_TRUE(d);
	// The next interval has 3 frames.
	EXPECT_FALSE(sel.addFrame(frame(6, 60, 0.5)));
	EXPECT_FALSE(sel.addFrame(frame(7, 70, 0.5)));
	EXPECT_TRUE(sel.addFrame(frame(8, 80, 0.5)));
	// Normal motion restores N_I = 5.
	sel.addFrame(frame(9, 90, 0.05));
	EXPECT_EQ(sel.currentInterval(), 5);
	// A still camera (D <= D_min) produces no keyframe.
	CSemanticKeyFrameSelector still;
	ASSERT_TRUE(still.addFrame(frame(0, 0)));
	for (int k = 1; k <= 10; k++) EXPECT_FALSE(still.addFrame(frame(k, 100, 0.001)));
}

TEST(KeyFrameSelector, BadOptions)
{
	CSemanticKeyFrameSelector::TOptions o;
	o.gamma = 1.5;
	yesslam_test::expectInputError([&] { CSemanticKeyFrameSelector s(o); }, {"gamma"});
	o = {};
	o.minMotion = 1;
	yesslam_test::expectInputError([&] { CSemanticKeyFrameSelector s(o); }, {"minMotion"});
}
