// The z-up export frame (issue 30 item 4): levelled by the floor, not by a desk top or by stray
// points under the floor, and by the camera's own axes when no floor is seen.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <random>

#include "TestUtils.h"
#include "mrpt_yesslam/io/WorldFrame.h"

using mrpt::math::TPoint3D;
using mrpt::poses::CPose3D;
using namespace mrpt_yesslam;

namespace
{
// A room in a z-up world: floor (z = 0), a desk top at 0.75 m holding more points than the floor
// seen, and a wall; 3 mm noise as a depth camera at 2 m.
std::vector<TPoint3D> room(bool floor, bool desk, std::mt19937& rng)
{
	std::normal_distribution<double> noise(0, 0.003);
	std::uniform_real_distribution<double> u(0, 1);
	std::vector<TPoint3D> w;
	if (floor)
		for (int i = 0; i < 4000; i++) w.emplace_back(0.5 + 3 * u(rng), -1.5 + 3 * u(rng), noise(rng));
	if (desk)
		for (int i = 0; i < 9000; i++) w.emplace_back(1.2 + 1.0 * u(rng), -0.6 + 1.2 * u(rng), 0.75 + noise(rng));
	for (int i = 0; i < 6000; i++) w.emplace_back(3.5 + noise(rng), -2 + 4 * u(rng), 0.2 + 2.3 * u(rng));
	return w;
}

// The first camera 1.4 m up, looking along +x, pitched 35 degrees down and rolled 4 degrees: its
// optical frame (x right, y down, z forward) in the world.
CPose3D firstCamera()
{
	const CPose3D body(0.0, 0.0, 1.4, 0.0, mrpt::DEG2RAD(35.0), mrpt::DEG2RAD(4.0));  // x forward, z up
	const CPose3D opticalInBody(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
	return body + opticalInBody;
}

double angleDeg(const CPose3D& a, const CPose3D& b)
{
	const auto R = (a.getRotationMatrix().asEigen().transpose() * b.getRotationMatrix().asEigen()).eval();
	return mrpt::RAD2DEG(std::acos(std::clamp((R.trace() - 1) / 2, -1.0, 1.0)));
}

// The map as SLAM has it: in the first camera's optical frame.
std::vector<TPoint3D> inMap(const std::vector<TPoint3D>& world, const CPose3D& cam)
{
	std::vector<TPoint3D> m;
	for (const auto& p : world) m.push_back(cam.inverseComposePoint(p));
	return m;
}
}  // namespace

TEST(WorldFrame, TheFloorLevelsTheFrameAndLiesAtZeroEvenUnderABusierDesk)
{
	std::mt19937 rng(3);
	auto world = room(true, true, rng);
	// Stray points a metre under the floor (reflections, flying pixels) are no floor.
	std::uniform_real_distribution<double> u(0, 1);
	for (int i = 0; i < 60; i++) world.emplace_back(1 + 2 * u(rng), -1 + 2 * u(rng), -1.0);
	const CPose3D cam = firstCamera();
	const TWorldFrame f = estimateZUpWorldFrame(inMap(world, cam), CPose3D());
	ASSERT_TRUE(f.floorSeen);
	EXPECT_NEAR(f.cameraHeight, 1.4, 0.01);
	// The true world frame is the answer: its x axis is the camera's view on the floor, its origin
	// the point of the floor under the camera.
	const CPose3D camInWorld = f.worldFromMap;  // T_world_map with map = the camera
	EXPECT_LT(angleDeg(camInWorld, cam), 0.3);
	EXPECT_NEAR(camInWorld.x(), 0, 0.01);
	EXPECT_NEAR(camInWorld.y(), 0, 0.01);
	EXPECT_NEAR(camInWorld.z(), 1.4, 0.01);
	EXPECT_EQ(f.kind, TWorldFrame::EKind::ZUp);
	EXPECT_NE(f.describe().find("floor at z = 0"), std::string::npos);
}

TEST(WorldFrame, WithoutAFloorTheFirstCamerasAxesLevelIt)
{
	std::mt19937 rng(4);
	const CPose3D cam = firstCamera();
	const TWorldFrame f = estimateZUpWorldFrame(inMap(room(false, false, rng), cam), CPose3D());
	EXPECT_FALSE(f.floorSeen);
	// z is the camera's up (-y), x its view (z), the origin the camera: a fixed axis permutation.
	const CPose3D expected(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
	EXPECT_LT(angleDeg(f.worldFromMap, expected), 1e-4);
	EXPECT_NEAR(f.worldFromMap.norm(), 0, 1e-9);
	EXPECT_NE(f.describe().find("no floor seen"), std::string::npos);
}

TEST(WorldFrame, TheHeaderStatesTheTransformAndReadsBack)
{
	std::mt19937 rng(5);
	const CPose3D cam = firstCamera();
	const TWorldFrame f = estimateZUpWorldFrame(inMap(room(true, false, rng), cam), CPose3D());
	TTrajectory t{TStampedPose::fromPose(1.0, CPose3D(0.1, 0.2, 0.3, 0.1, 0.2, 0.3))};
	const yesslam_test::TempDir d("world_frame");
	const std::string path = d / "t.txt";
	writeTumTrajectory(path, toWorldFrame(t, f.worldFromMap), "a run\n" + f.describe());
	const auto back = readWorldFromMap(path);
	ASSERT_TRUE(back.has_value());
	EXPECT_LT(angleDeg(*back, f.worldFromMap), 1e-4);
	EXPECT_NEAR((back->asVectorVal() - f.worldFromMap.asVectorVal()).norm(), 0, 1e-6);
	// The file's pose is T_world_map composed with the map's.
	const auto p = readTumTrajectory(path)[0].asPose();
	EXPECT_NEAR((p.asVectorVal() - (f.worldFromMap + t[0].asPose()).asVectorVal()).norm(), 0, 1e-6);
	// Ground truth states none.
	writeTumTrajectory(path, t, "ground truth");
	EXPECT_FALSE(readWorldFromMap(path).has_value());
}
