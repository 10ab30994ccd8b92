// CGeometricDynamicCheck: which keypoints are uncertain, and that uncertain matches moving with a
// person cannot drag the pose (while the same matches do drag it without the check), that
// uncertain matches on the static world still join, and that a view filled by a person gives no
// pose at all.
#include <gtest/gtest.h>

#include <random>

#include "TestUtils.h"
#include "mrpt_yesslam/dynamic/CGeometricDynamicCheck.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

TEST(GeometricCheck, UncertainKeypointsAreUnmaskedOnesInADynamicBox)
{
	TFeatures f;
	for (const cv::Point2f p : {cv::Point2f(50, 50), cv::Point2f(150, 150), cv::Point2f(205, 150), cv::Point2f(150, 150), cv::Point2f(450, 300)})
	{
		f.keypoints.emplace_back(p, 7.f);
		f.depth.push_back(2.f);
	}
	f.dynamic = {false, false, false, true, false};
	TDetection person, chair;
	person.dynamic = true;
	person.box = {100, 100, 100, 200};	// grown by 10 %: x in [90, 210]
	chair.dynamic = false;
	chair.box = {400, 250, 100, 100};
	CGeometricDynamicCheck check{CGeometricDynamicCheck::TOptions()};
	check.classify(f, {person, chair}, {640, 480});
	EXPECT_EQ(f.uncertain, (std::vector<bool>{false, true, true, false, false}));
	CGeometricDynamicCheck::TOptions off;
	off.enabled = false;
	CGeometricDynamicCheck(off).classify(f, {person, chair}, {640, 480});
	EXPECT_EQ(f.uncertain, (std::vector<bool>(5, false)));
}

namespace
{
// Observations of `n` points seen from `Twc`: static ones at their place; "person" ones measured
// where they are now but matched to map points where the person was (moved by `shift`).
void observe(
	std::vector<TPoseObservation>& obs, std::vector<bool>& uncertain, const mrpt::poses::CPose3D& Twc, int n, bool isUncertain,
	const Eigen::Vector3d& shift, std::mt19937& rng)
{
	const auto K = fr3Camera();
	std::uniform_real_distribution<double> u(-1, 1);
	std::normal_distribution<double> px(0, 0.5);
	for (int i = 0; i < n; i++)
	{
		const double z = 2.0 + 1.0 * std::abs(u(rng));
		const double x = 1.2 * u(rng) * z / 2.5, y = 0.9 * u(rng) * z / 2.5;
		double wx, wy, wz;
		Twc.composePoint(x, y, z, wx, wy, wz);
		TPoseObservation o;
		o.world = Eigen::Vector3d(wx, wy, wz) + shift;	// the map point
		o.pixel = {K.fx() * x / z + K.cx() + px(rng), K.fy() * y / z + K.cy() + px(rng)};
		o.depth = z;
		o.sigmaZ = 0.0025 * z * z;
		obs.push_back(o);
		uncertain.push_back(isUncertain);
	}
}

double translationError(const mrpt::poses::CPose3D& a, const mrpt::poses::CPose3D& b)
{
	return (a.asVectorVal().head<3>() - b.asVectorVal().head<3>()).norm();
}
}  // namespace

TEST(GeometricCheck, UncertainMatchesMovingWithAPersonCannotDragThePose)
{
	std::mt19937 rng(3);
	const mrpt::poses::CPose3D truth(0.3, -0.1, 0.05, 0.1, 0.05, -0.02);
	const mrpt::poses::CPose3D guess(0.28, -0.08, 0.04, 0.09, 0.05, -0.02);
	std::vector<TPoseObservation> obs;
	std::vector<bool> uncertain;
	observe(obs, uncertain, truth, 50, false, Eigen::Vector3d::Zero(), rng);  // certain static
	observe(obs, uncertain, truth, 20, true, Eigen::Vector3d::Zero(), rng);  // uncertain, static: background between legs
	observe(obs, uncertain, truth, 150, true, Eigen::Vector3d(0.04, 0, 0.03), rng);  // uncertain, on a person who moved 5 cm
	const CPoseOptimizer optimizer{CPoseOptimizer::TOptions()};
	const auto K = fr3Camera();

	CGeometricDynamicCheck::TOptions off;
	off.enabled = false;
	const TPoseEstimate dragged = CGeometricDynamicCheck(off).refine(optimizer, obs, uncertain, K, guess);
	ASSERT_TRUE(dragged.ok);
	EXPECT_GT(translationError(dragged.cameraInWorld, truth), 0.02) << "the person's matches should outvote the static ones without the check";

	CGeometricDynamicCheck::TStats st;
	const TPoseEstimate e = CGeometricDynamicCheck(CGeometricDynamicCheck::TOptions()).refine(optimizer, obs, uncertain, K, guess, &st);
	ASSERT_TRUE(e.ok);
	EXPECT_TRUE(st.applied);
	EXPECT_LT(translationError(e.cameraInWorld, truth), 0.005);
	// The static uncertain matches joined, the person's did not.
	std::size_t staticJoined = 0, personJoined = 0;
	for (std::size_t i = 50; i < 70; i++) staticJoined += e.inlier[i];
	for (std::size_t i = 70; i < obs.size(); i++) personJoined += e.inlier[i];
	EXPECT_GE(staticJoined, 18u);
	EXPECT_LE(personJoined, 8u);
}

TEST(GeometricCheck, AViewFilledByAPersonGivesNoPose)
{
	std::mt19937 rng(4);
	const mrpt::poses::CPose3D truth(0.1, 0, 0, 0, 0, 0);
	std::vector<TPoseObservation> obs;
	std::vector<bool> uncertain;
	observe(obs, uncertain, truth, 12, false, Eigen::Vector3d::Zero(), rng);
	observe(obs, uncertain, truth, 200, true, Eigen::Vector3d(0.3, 0, 0), rng);
	const CPoseOptimizer optimizer{CPoseOptimizer::TOptions()};
	CGeometricDynamicCheck::TStats st;
	const TPoseEstimate e = CGeometricDynamicCheck(CGeometricDynamicCheck::TOptions()).refine(optimizer, obs, uncertain, fr3Camera(), truth, &st);
	EXPECT_FALSE(e.ok);
	EXPECT_TRUE(st.blinded);
	EXPECT_EQ(e.numInliers, 0u);
	// Few features of either kind (a bare wall): the check stands aside.
	obs.resize(12 + 5);
	uncertain.resize(12 + 5);
	EXPECT_TRUE(CGeometricDynamicCheck(CGeometricDynamicCheck::TOptions()).refine(optimizer, obs, uncertain, fr3Camera(), truth, &st).ok);
	EXPECT_FALSE(st.blinded);
}
