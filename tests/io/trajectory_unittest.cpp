// Tests of the TUM trajectory reader/writer: separators, comments, strict errors, atomic writes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "TestUtils.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

TEST(Trajectory, ParsesSpacesCommasTabsAndComments)
{
	const auto t = parseTumTrajectory(
		"# header\n\n1.5 1 2 3 0 0 0 1\n  # indented "
		"comment\n2.5,4,5,6,0,0,0.7071068,0.7071068\r\n3.5\t7\t8\t9\t0\t0\t0\t1\n",
		"x.txt");
	ASSERT_EQ(t.size(), 3u);
	EXPECT_DOUBLE_EQ(t[0].t, 1.5);
	EXPECT_DOUBLE_EQ(t[1].ty, 5);
	EXPECT_DOUBLE_EQ(t[1].qz, 0.7071068);
	EXPECT_DOUBLE_EQ(t[2].tz, 9);
	// The orientation of the second pose is 90 degrees about z.
	EXPECT_NEAR(t[1].asPose().yaw(), M_PI / 2, 1e-6);
}

TEST(Trajectory, RejectsMalformedLinesNamingFileAndLine)
{
	expectInputError([] { parseTumTrajectory("# c\n1 2 3 4 5 6\n", "traj.txt"); },
					 {"traj.txt", "line 2", "expected 8"});
	expectInputError([] { parseTumTrajectory("1 2 3 nan 0 0 0 1\n", "a.txt"); }, {"a.txt", "line 1", "nan"});
	expectInputError([] { parseTumTrajectory("1 2 3 inf 0 0 0 1\n", "a.txt"); }, {"not a finite number"});
	expectInputError([] { parseTumTrajectory("1 2 3 4 0 0 0 0\n", "q.txt"); }, {"q.txt", "zero norm"});
	expectInputError([] { parseTumTrajectory("1 2 3 4x 0 0 0 1\n", "q.txt"); }, {"'4x'"});
	expectInputError([] { readTumTrajectory("/nonexistent/traj.txt"); }, {"/nonexistent/traj.txt", "not found"});
}

TEST(Trajectory, WriteReadRoundTripIsAtomic)
{
	TempDir dir("traj");
	TTrajectory t;
	for (int i = 0; i < 50; i++)
	{
		const mrpt::poses::CPose3D p(0.1 * i, -0.2 * i, 1.0, 0.01 * i, 0.02 * i, -0.03 * i);
		t.push_back(TStampedPose::fromPose(1305031102.175304 + i / 30.0, p));
	}
	const std::string path = dir / "out.txt";
	writeTumTrajectory(path, t, "written by a test\nsecond line");
	const auto back = readTumTrajectory(path);
	ASSERT_EQ(back.size(), t.size());
	for (std::size_t i = 0; i < t.size(); i++)
	{
		EXPECT_NEAR(back[i].t, t[i].t, 1e-6);
		EXPECT_NEAR(back[i].tx, t[i].tx, 1e-9);
		const auto d = back[i].asPose() - t[i].asPose();
		EXPECT_LT(d.norm(), 1e-8);
	}
	// No temporary file is left behind, and an existing file is replaced whole.
	int files = 0;
	for (const auto& e : std::filesystem::directory_iterator(dir.path())) files += e.is_regular_file();
	EXPECT_EQ(files, 1);
	writeTumTrajectory(path, TTrajectory(t.begin(), t.begin() + 2));
	EXPECT_EQ(readTumTrajectory(path).size(), 2u);
}

TEST(Trajectory, WritingIntoMissingFolderFails)
{
	expectInputError([] { writeTumTrajectory("/nonexistent_dir_yesslam/x.txt", TTrajectory{}); },
					 {"/nonexistent_dir_yesslam/x.txt"});
}

TEST(Trajectory, LostFramesBetweenTwoTrackedOnesArePlacedBetweenThemByTime)
{
	// Tracked at t = 0 (origin) and t = 4 (0.4 m along x, turned 40 degrees); lost in between
	// (coasted far off), and lost before the first and after the last tracked pose.
	const double deg = M_PI / 180;
	TTrajectory t;
	std::vector<bool> tracked;
	auto add = [&](double time, const mrpt::poses::CPose3D& p, bool ok)
	{
		t.push_back(TStampedPose::fromPose(time, p));
		tracked.push_back(ok);
	};
	add(-1, mrpt::poses::CPose3D(5, 5, 5, 0, 0, 0), false);
	add(0, mrpt::poses::CPose3D(), true);
	for (int k = 1; k <= 3; k++) add(k, mrpt::poses::CPose3D(1.0 * k, -0.3 * k, 0, -20 * k * deg, 0, 0), false);
	add(4, mrpt::poses::CPose3D(0.4, 0, 0, 40 * deg, 0, 0), true);
	add(5, mrpt::poses::CPose3D(2, 2, 2, 0, 0, 0), false);
	interpolateUntracked(t, tracked);
	for (int k = 1; k <= 3; k++)
	{
		const mrpt::poses::CPose3D p = t[static_cast<std::size_t>(k) + 1].asPose();
		EXPECT_NEAR(p.x(), 0.1 * k, 1e-9);
		EXPECT_NEAR(p.y(), 0, 1e-9);
		EXPECT_NEAR(p.yaw(), 10 * k * deg, 1e-9);
		EXPECT_NEAR(p.pitch(), 0, 1e-9);
		EXPECT_EQ(t[static_cast<std::size_t>(k) + 1].t, k);
	}
	// Runs without a tracked pose on both sides stay as written.
	EXPECT_EQ(t.front().tx, 5);
	EXPECT_EQ(t.back().tx, 2);
	EXPECT_NEAR(t[5].asPose().yaw(), 40 * deg, 1e-9);
}
