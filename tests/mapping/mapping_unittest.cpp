// Local bundle adjustment: the cost's derivatives, and that BA pulls perturbed keyframes and points
// back to the truth and removes observations that cannot fit.
#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <array>

#include <cmath>
#include <random>
#ifndef OUTLIER_PX
#define OUTLIER_PX 40
#endif

#include "TestUtils.h"
#include "mrpt_yesslam/optimize/BundleCosts.h"
#include "mrpt_yesslam/mapping/CLocalMapper.h"
#include "mrpt_yesslam/geometry/CPoseOptimizer.h"

using namespace mrpt_yesslam;

namespace
{
std::shared_ptr<TFrame> observe(std::size_t id, const mrpt::poses::CPose3D& Twc,
								const std::vector<mrpt::math::TPoint3D>& world, std::vector<TPointId> ids,
								std::mt19937& rng)
{
	return yesslam_test::observeWorld(id, Twc, world, std::move(ids), rng);
}

double positionError(const mrpt::poses::CPose3D& a, const mrpt::poses::CPose3D& b)
{
	return std::hypot(a.x() - b.x(), a.y() - b.y(), a.z() - b.z());
}

// One point P seen from one place (the origin) by two fixed keyframes, 0 and 1, with no baseline:
// only the depths say how far it is. Keyframe k reads `depths[k]` at pyramid level `octaves[k]`;
// the window starts the point at `start`.
TBundleWindow onePointFromOnePlace(const mrpt::img::TCamera& K, const mrpt::math::TPoint3D& P,
								   const std::array<double, 2>& depths, const std::array<int, 2>& octaves,
								   const mrpt::math::TPoint3D& start)
{
	const double u = K.fx() * P.x / P.z + K.cx(), v = K.fy() * P.y / P.z + K.cy();
	TBundleWindow w;
	for (TKeyFrameId k : {0, 1})
	{
		auto f = std::make_shared<TFeatures>();
		f->keypoints.push_back(cv::KeyPoint(static_cast<float>(u), static_cast<float>(v), 31.f, -1, 0, octaves[k]));
		f->depth.push_back(static_cast<float>(depths[k]));
		f->dynamic.push_back(false);
		f->descriptors = cv::Mat::zeros(1, 32, CV_8U);
		w.keyFrames.push_back(k);
		w.fixedKeyFrames.push_back(k);
		w.poses[k] = mrpt::poses::CPose3D();
		w.features[k] = f;
		w.cameras[k] = K;
	}
	w.points = {0};
	w.positions = {start};
	w.observations = {{{0, 0}, {1, 0}}};
	return w;
}
}  // namespace

TEST(BundleCosts, RgbdReprojectionJacobiansMatchNumeric)
{
	for (double z : {2.4, 0.0})  // with and without depth
	{
		const TRgbdReprojectionCost c(310, 250, z, 1.2, 0.0025 * z * z, 535.4, 539.2, 320.1, 247.6);
		ceres::AutoDiffCostFunction<TRgbdReprojectionCost, 3, 3, 3, 3> cost(new TRgbdReprojectionCost(c));
		double rv[3] = {0.1, -0.2, 0.05}, t[3] = {0.2, -0.1, 0.3}, X[3] = {0.4, 0.3, 2.5};
		std::vector<const double*> params = {rv, t, X};
		ceres::NumericDiffOptions nd;
		const std::vector<const ceres::Manifold*>* noManifold = nullptr;
		ceres::GradientChecker checker(&cost, noManifold, nd);
		// No ProbeResults: its Eigen matrices are allocated inside libceres with other alignment
		// settings than ours (see tracking/pose_unittest.cpp).
		EXPECT_TRUE(checker.Probe(params.data(), 1e-6, nullptr));
		// The depth residual: not zero for this point when there is depth.
		double r[3];
		c(rv, t, X, r);
		EXPECT_EQ(z <= 0, r[2] == 0.0);
	}
}

TEST(BundleCosts, TheHandWrittenJacobiansAreAutomaticDifferentiationsOwn)
{
	// Bundle adjustment solves with CRgbdReprojectionCostAnalytic (issue 41: dual numbers were half
	// of every solve). Its residuals and Jacobians must be those automatic differentiation gives
	// for TRgbdReprojectionCost, at large and tiny rotations (the right Jacobian's series), with and
	// without depth, on any pyramid level.
	struct Case
	{
		double rv[3], t[3], X[3], z, sigma;
	};
	const std::vector<Case> cases = {{{0.1, -0.2, 0.05}, {0.2, -0.1, 0.3}, {0.4, 0.3, 2.5}, 2.4, 1.0},
									 {{1.2, 0.4, -0.9}, {-0.3, 0.2, 1.5}, {-0.8, 0.5, 1.1}, 0.0, 1.44},
									 {{1e-6, -2e-6, 5e-7}, {0.0, 0.0, 0.0}, {0.3, -0.2, 3.0}, 3.1, 2.0736},
									 {{0.0, 0.0, 0.0}, {0.1, 0.0, -0.2}, {-0.5, 0.4, 4.2}, 4.0, 1.2},
									 {{2.9, -0.1, 0.2}, {0.0, 0.1, 0.0}, {0.2, 0.1, -2.0}, 1.5, 1.0}};
	for (const auto& k : cases)
	{
		SCOPED_TRACE(k.X[2]);
		const TRgbdReprojectionCost c(310, 250, k.z, k.sigma, 0.0025 * k.z * k.z * k.sigma, 535.4, 539.2, 320.1, 247.6);
		ceres::AutoDiffCostFunction<TRgbdReprojectionCost, 3, 3, 3, 3> automatic(new TRgbdReprojectionCost(c));
		const CRgbdReprojectionCostAnalytic analytic(c);
		const double* params[3] = {k.rv, k.t, k.X};
		double ra[3], rb[3], ja[3][9], jb[3][9];
		double* pa[3] = {ja[0], ja[1], ja[2]};
		double* pb[3] = {jb[0], jb[1], jb[2]};
		ASSERT_TRUE(automatic.Evaluate(params, ra, pa));
		ASSERT_TRUE(analytic.Evaluate(params, rb, pb));
		for (int i = 0; i < 3; i++) EXPECT_NEAR(ra[i], rb[i], 1e-9 * (1 + std::abs(ra[i])));
		for (int b = 0; b < 3; b++)
			for (int i = 0; i < 9; i++)
				EXPECT_NEAR(ja[b][i], jb[b][i], 1e-7 * (1 + std::abs(ja[b][i]))) << "block " << b << " entry " << i;
	}
}

TEST(LocalMapper, BundleAdjustmentRecoversPerturbedKeyFramesAndPoints)
{
	std::mt19937 rng(7);
	std::uniform_real_distribution<double> ux(-1.5, 1.5), uy(-1.0, 1.0), uz(2.0, 4.0);
	std::vector<mrpt::math::TPoint3D> world;
	for (int i = 0; i < 150; i++) world.emplace_back(ux(rng), uy(rng), uz(rng));
	const std::vector<mrpt::poses::CPose3D> truth = {mrpt::poses::CPose3D(),
													 mrpt::poses::CPose3D(0.10, 0.02, 0.0, 0.05, 0.0, 0.0),
													 mrpt::poses::CPose3D(0.20, -0.03, 0.05, 0.10, 0.02, 0.0)};

	CSparseMap map;
	// Keyframe 0 creates the points from depth; the others observe the same ones.
	std::vector<TPointId> none(world.size(), -1), ids(world.size());
	map.addKeyFrame(observe(0, truth[0], world, none, rng), 10.0);
	for (std::size_t j = 0; j < ids.size(); j++) ids[j] = static_cast<TPointId>(j);
	// Keyframes 1 and 2 start 3 cm off, and two observations of keyframe 2 are gross outliers.
	for (std::size_t k = 1; k < 3; k++)
	{
		auto f = observe(k, truth[k], world, ids, rng);
		f->pose = truth[k] + mrpt::poses::CPose3D(0.03, -0.02, 0.01, 0.01, 0.0, 0.0);
		if (k == 2)
			for (std::size_t j : {5, 9}) f->features.keypoints[j].pt.x += OUTLIER_PX;
		map.addKeyFrame(f, 10.0);
	}
	ASSERT_EQ(map.numKeyFrames(), 3u);
	ASSERT_GT(positionError(map.keyFramePose(2), truth[2]), 0.03);

	CLocalMapper::TOptions o;
	o.iterations = 30;
	CLocalMapper mapper(o, map);
	const TBundleStats st = mapper.bundleAdjust(2);
	EXPECT_EQ(st.fixedKeyFrames, 1u);  // keyframe 0 anchors the map
	EXPECT_EQ(st.keyFrames, 2u);
	EXPECT_LT(st.finalCost, 0.1 * st.initialCost);  // what is left is the two outliers' (Huber) cost
	EXPECT_EQ(st.outliers, 2u);
	for (std::size_t k = 0; k < 3; k++) EXPECT_LT(positionError(map.keyFramePose(k), truth[k]), 2e-3) << k;
	EXPECT_EQ(positionError(map.keyFramePose(0), truth[0]), 0.0);
	// The outlier observations are gone from keyframe 2; the points survive (other views).
	const CKeyFrame kf2 = map.keyFrame(2);
	EXPECT_EQ(kf2.mapPoints[5], -1);
	EXPECT_EQ(kf2.mapPoints[9], -1);
	EXPECT_EQ(kf2.mapPoints[6], 6);
	EXPECT_EQ(map.numPoints(), world.size());
}

TEST(LocalMapper, CullsYoungPointsThatTrackingRarelyFinds)
{
	std::mt19937 rng(3);
	std::vector<mrpt::math::TPoint3D> world;
	for (int i = 0; i < 30; i++) world.emplace_back(0.05 * i - 0.7, 0.02 * i - 0.3, 2.0 + 0.03 * i);
	CSparseMap map;
	map.addKeyFrame(observe(0, mrpt::poses::CPose3D(), world, std::vector<TPointId>(world.size(), -1), rng), 10.0);
	// Points 0-9 were in view 10 times and found once; the rest were found every time.
	std::vector<TPointId> visible, found;
	for (TPointId j = 0; j < 30; j++)
		for (int k = 0; k < 10; k++)
		{
			visible.push_back(j);
			if (j >= 10 || k == 0) found.push_back(j);
		}
	map.countTracking(visible, found);
	EXPECT_EQ(map.cullRecentPoints(0, 0.25, 1), 10u);
	EXPECT_EQ(map.numPoints(), 20u);
	EXPECT_EQ(map.keyFrame(0).mapPoints[3], -1);
	EXPECT_EQ(map.keyFrame(0).mapPoints[12], 12);
}

TEST(BundleAdjustment, ACoarseKeypointsDepthCountsLessThanAFineOnes)
{
	// One point seen from one place by two keyframes (no baseline: only the depths say how far it
	// is): a fine keypoint (level 0) measures its true depth, a coarse one (level 5, sigma 2.5 px)
	// a depth 5 cm too far. The depth of a coarse keypoint is read where the keypoint is, known to
	// 2.5 px, so it counts as its pixel does (ORB-SLAM2's virtual right coordinate): the point stays
	// within 1 cm of the truth. Weighed alike, it settled half way (2.5 cm off).
	const mrpt::img::TCamera K = yesslam_test::fr3Camera();
	const mrpt::math::TPoint3D P(0.3, -0.2, 3.0);
	const TBundleWindow w = onePointFromOnePlace(K, P, {P.z, P.z + 0.05}, {0, 5}, {P.x, P.y, P.z + 0.03});
	TBundleSolveOptions o;
	o.iterations = 50;
	const TBundleSolution s = solveBundle(w, o);
	ASSERT_EQ(s.positions.size(), 1u);
	const double err = std::hypot(s.positions[0].x - P.x, s.positions[0].y - P.y, s.positions[0].z - P.z);
	EXPECT_LT(err, 0.01) << "z " << s.positions[0].z;
	EXPECT_GT(s.positions[0].z, P.z + 0.001) << "the coarse depth still counts a little";
}

TEST(BundleAdjustment, BeyondFarDepthAKeypointsDepthIsNotAMeasurement)
{
	// [Camera] farDepth: one point 4 m away seen from one place by two keyframes whose depths both
	// read 12 cm too far (a far-depth bias, as a real structured-light sensor's). With every depth
	// a measurement bundle adjustment pulls the point along its ray to the biased depth; with
	// farDepth = 3 m the far depths are not in the cost, and a point no keyframe of the window
	// measures nearer keeps its position (as one without depth: no baseline places it along its
	// rays). A point at 2 m is still pulled by its depth.
	const mrpt::img::TCamera K = yesslam_test::fr3Camera();
	const auto solve = [&](double z, double farDepth)
	{
		const mrpt::math::TPoint3D P(0.2, -0.1, z);
		const TBundleWindow w = onePointFromOnePlace(K, P, {z + 0.12, z + 0.12}, {0, 0}, P);
		TBundleSolveOptions o;
		o.iterations = 50;
		o.depthNoise.farDepth = farDepth;
		const TBundleSolution s = solveBundle(w, o);
		EXPECT_EQ(s.positions.size(), 1u);
		return s.positions.empty() ? 0.0 : s.positions[0].z - P.z;
	};
	EXPECT_GT(solve(4.0, 0.0), 0.08) << "every depth a measurement: pulled to the biased depth";
	EXPECT_LT(std::abs(solve(4.0, 3.0)), 0.005) << "beyond farDepth: the biased depths do not move it";
	EXPECT_GT(solve(2.0, 3.0), 0.08) << "a near depth is still a measurement";
}

TEST(BundleAdjustment, AKeyFrameTheWindowCannotPlaceKeepsItsPose)
{
	// Issue 27: a keyframe made from a frame tracked against the last frame's depth points alone
	// linked 2 map points; its 98 new points move with it, so local BA placed it by those 2 and moved
	// it 28 cm (crowd seed 3, rolling shutter: 6.3 mm ATE online, 17.4 mm after the run). Here
	// keyframe 1 sees 40 points of its own and 3 that the fixed keyframe 0 sees too, mismatched 25 px
	// off: with fewer than TBundleSolveOptions::minSharedObservations shared observations it keeps
	// the pose tracking gave it; allowed to move (0), it follows the mismatches.
	const mrpt::img::TCamera K = yesslam_test::fr3Camera();
	const mrpt::poses::CPose3D T1(0.1, 0, 0, 0, 0, 0);
	const std::vector<mrpt::math::TPoint3D> shared = {{-0.3, 0, 2}, {0.3, 0.1, 2.5}, {0, -0.2, 3}};
	TBundleWindow w;
	auto f0 = std::make_shared<TFeatures>(), f1 = std::make_shared<TFeatures>();
	const auto see = [&](TFeatures& f, const mrpt::poses::CPose3D& T, const mrpt::math::TPoint3D& P, double shiftU)
	{
		const auto c = (-T).composePoint(P);
		f.keypoints.push_back(cv::KeyPoint(static_cast<float>(K.fx() * c.x / c.z + K.cx() + shiftU),
										   static_cast<float>(K.fy() * c.y / c.z + K.cy()), 31.f));
		f.depth.push_back(static_cast<float>(c.z));
		f.dynamic.push_back(false);
		return f.keypoints.size() - 1;
	};
	for (const auto& P : shared)
	{
		w.observations.push_back({{0, see(*f0, {}, P, 0)}, {1, see(*f1, T1, P, 25)}});
		w.points.push_back(static_cast<TPointId>(w.points.size()));
		w.positions.push_back(P);
	}
	for (int i = 0; i < 40; i++)
	{
		const mrpt::math::TPoint3D P(0.1 * (i % 8) - 0.3, 0.1 * (i / 8) - 0.2, 2.0 + 0.05 * (i % 5));
		w.observations.push_back({{1, see(*f1, T1, P, 0)}});
		w.points.push_back(static_cast<TPointId>(w.points.size()));
		w.positions.push_back(P);
	}
	f0->descriptors = cv::Mat::zeros(static_cast<int>(f0->keypoints.size()), 32, CV_8U);
	f1->descriptors = cv::Mat::zeros(static_cast<int>(f1->keypoints.size()), 32, CV_8U);
	w.keyFrames = {1};
	w.fixedKeyFrames = {0};
	w.poses = {{0, mrpt::poses::CPose3D()}, {1, T1}};
	w.features = {{0, f0}, {1, f1}};
	w.cameras = {{0, K}, {1, K}};
	TBundleSolveOptions o;
	o.iterations = 50;
	const auto moved = [&](std::size_t minShared)
	{
		o.minSharedObservations = minShared;
		const TBundleSolution s = solveBundle(w, o);
		EXPECT_EQ(s.stats.heldKeyFrames, minShared > 3 ? 1u : 0u);
		const auto& p = s.poses.at(1);
		return std::hypot(p.x() - T1.x(), p.y() - T1.y(), p.z() - T1.z()) + std::abs(p.yaw() - T1.yaw()) +
			   std::abs(p.pitch());
	};
	EXPECT_LT(moved(TBundleSolveOptions().minSharedObservations), 1e-9) << "held where tracking put it";
	EXPECT_GT(moved(0), 0.01) << "free, the three mismatches place it";
}

TEST(BundleAdjustment, ASolveWhoseResultWentStaleStopsAtTheNextIteration)
{
	// Issue 28 item 6: a global BA whose window a newer correction has made stale ran on to the end
	// and was then refused; TBundleSolveOptions::cancelled (CLoopCloser asks whether the map's
	// correction generation changed) stops it after the current iteration.
	std::mt19937 rng(11);
	std::vector<mrpt::math::TPoint3D> world;
	for (int i = 0; i < 60; i++)
		world.emplace_back(0.05 * (i % 10) - 0.25, 0.05 * (i / 10) - 0.15, 2.0 + 0.01 * (i % 7));
	CSparseMap map;
	std::vector<TPointId> ids;
	map.addKeyFrame(observe(0, mrpt::poses::CPose3D(), world, std::vector<TPointId>(world.size(), -1), rng), 10.0);
	for (TPointId j = 0; j < 60; j++) ids.push_back(j);
	map.addKeyFrame(observe(1, mrpt::poses::CPose3D(0.1, 0, 0, 0.05, 0, 0), world, ids, rng), 10.0);
	map.addKeyFrame(observe(2, mrpt::poses::CPose3D(0.2, 0.02, 0, 0.1, 0, 0), world, ids, rng), 10.0);
	TBundleWindow w = map.globalBundleWindow();
	for (auto& [k, p] : w.poses)
		if (k != 0) p = p + mrpt::poses::CPose3D(0.02, -0.01, 0.01, 0.01, 0, 0);  // something to optimise
	TBundleSolveOptions o;
	o.iterations = 50;
	const TBundleSolution full = solveBundle(w, o);
	EXPECT_FALSE(full.stats.cancelled);
	ASSERT_GT(full.stats.iterations, 2);
	int asked = 0;
	o.cancelled = [&] { return ++asked >= 2; };
	const TBundleSolution stopped = solveBundle(w, o);
	EXPECT_TRUE(stopped.stats.cancelled);
	EXPECT_EQ(asked, 2);
	EXPECT_LE(stopped.stats.iterations, 2);
	EXPECT_TRUE(stopped.poses.empty()) << "a stale result is not handed back";
}
