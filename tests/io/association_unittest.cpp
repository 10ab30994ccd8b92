// The fast association must equal associate.py's quadratic greedy on any input.
#include <gtest/gtest.h>

#include <random>

#include "TestUtils.h"
#include "mrpt_yesslam/io/Association.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"

using namespace mrpt_yesslam;

TEST(Association, SmallExampleGreedyOneToOne)
{
	// b=1.011 is closest to a=1.01 (0.001) and must not be reused for a=1.02 (0.009).
	const std::vector<double> a = {1.00, 1.01, 1.02, 5.0};
	const std::vector<double> b = {1.011, 1.025, 9.0};
	const auto m = associateTimestamps(a, b, 0.0, 0.02);
	ASSERT_EQ(m.size(), 2u);
	EXPECT_EQ(m[0], std::make_pair(std::size_t(1), std::size_t(0)));
	EXPECT_EQ(m[1], std::make_pair(std::size_t(2), std::size_t(1)));
}

TEST(Association, EqualsQuadraticGreedyOnRandomStamps)
{
	std::mt19937 rng(7);
	for (int trial = 0; trial < 200; trial++)
	{
		std::uniform_int_distribution<int> nDist(0, 120);
		const int na = nDist(rng), nb = nDist(rng);
		std::uniform_real_distribution<double> t(0.0, 2.0);
		std::vector<double> a(na), b(nb);
		for (auto& x : a) x = 1.3e9 + t(rng);
		for (auto& x : b) x = 1.3e9 + t(rng);
		// Quantise some stamps to force exact ties and duplicates.
		if (trial % 3 == 0)
		{
			for (auto& x : a) x = 1.3e9 + std::round((x - 1.3e9) * 100) / 100;
			for (auto& x : b) x = 1.3e9 + std::round((x - 1.3e9) * 100) / 100;
		}
		const double offset = (trial % 4 == 1) ? 0.013 : 0.0;
		const double maxDiff = (trial % 5 == 2) ? 0.05 : 0.02;
		EXPECT_EQ(associateTimestamps(a, b, offset, maxDiff), associateTimestampsQuadratic(a, b, offset, maxDiff))
			<< "trial " << trial;
	}
}

TEST(Association, RealTumListsMatchQuadratic)
{
	// fr1/xyz rgb.txt and depth.txt (TUM RGB-D, CC BY 4.0); their third header line has no '#'.
	const auto rgb = readTumFileList(yesslam_test::sharedFile("data/tum_eval_trajectories/fr1_xyz_rgb.txt"));
	const auto depth = readTumFileList(yesslam_test::sharedFile("data/tum_eval_trajectories/fr1_xyz_depth.txt"));
	ASSERT_EQ(rgb.size(), 798u);
	ASSERT_EQ(depth.size(), 798u);
	std::vector<double> a, b;
	for (const auto& e : rgb) a.push_back(e.t);
	for (const auto& e : depth) b.push_back(e.t);
	const auto fast = associateTimestamps(a, b);
	EXPECT_EQ(fast, associateTimestampsQuadratic(a, b));
	EXPECT_GT(fast.size(), 700u);
	for (const auto& [i, j] : fast) EXPECT_LT(std::abs(a[i] - b[j]), 0.02);
}
