// The sensor statistics that hold the simulator against real frames, on frames of known content.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "mrpt_yesslam/sim/CSensorStatistics.h"

using namespace mrpt_yesslam;

namespace
{
// A slanted wall at 2.1-2.3 m with white depth noise `sigma`; the top `holeRows` rows have no depth.
cv::Mat noisyWall(double sigma, unsigned seed, int holeRows = 0)
{
	std::mt19937 rng(seed);
	std::normal_distribution<double> n(0, sigma);
	cv::Mat d(480, 640, CV_32F);
	for (int y = 0; y < d.rows; y++)
		for (int x = 0; x < d.cols; x++)
			d.at<float>(y, x) = y < holeRows ? 0.f : static_cast<float>(2.1 + 0.0003 * x + n(rng));
	return d;
}

// Blocks of random grey levels: corners everywhere.
cv::Mat blocks(int square)
{
	cv::Mat small(480 / square, 640 / square, CV_8U), g;
	cv::theRNG().state = 12345;
	cv::randu(small, 0, 256);
	cv::resize(small, g, cv::Size(640, 480), 0, 0, cv::INTER_NEAREST);
	return g;
}
}  // namespace

TEST(SensorStatistics, MeasureDepthNoiseValidDepthTextureAndSharpness)
{
	CSensorStatistics sharp, blurred, flat;
	cv::Mat blur;
	cv::GaussianBlur(blocks(8), blur, cv::Size(), 2.0);
	for (unsigned k = 0; k < 3; k++)
	{
		sharp.addFrame(blocks(8), noisyWall(0.005, k, 96));  // 96 of 480 rows without depth
		blurred.addFrame(blur, noisyWall(0.005, k));
		flat.addFrame(cv::Mat(480, 640, CV_8U, cv::Scalar(128)), noisyWall(0.005, k));
	}
	const auto r = sharp.result();
	EXPECT_EQ(r.frames, 3u);
	EXPECT_NEAR(r.validDepthShare, 0.8, 1e-9);
	EXPECT_GT(r.texturedCellShare, 0.9);
	EXPECT_EQ(flat.result().texturedCellShare, 0.0) << "a flat grey image has no corner";
	EXPECT_LT(blurred.result().sharpness, 0.2 * r.sharpness) << "blur lowers the Laplacian's variance";
	EXPECT_LT(flat.result().colourNoise, 0.01) << "no noise on a flat grey image";
	{
		// Immerkaer's estimate recovers the sigma of white noise, and blocks' edges barely move it.
		CSensorStatistics noisy, noisyBlocks;
		for (unsigned k = 0; k < 2; k++)
		{
			cv::Mat n(480, 640, CV_16S), img, img2;
			cv::theRNG().state = 11 + k;
			cv::randn(n, 0, 2.0);
			cv::Mat base16;
			cv::Mat(480, 640, CV_8U, cv::Scalar(128)).convertTo(base16, CV_16S);
			cv::Mat(base16 + n).convertTo(img, CV_8U);
			cv::Mat b16;
			blocks(32).convertTo(b16, CV_16S);
			cv::Mat(b16 + n).convertTo(img2, CV_8U);
			noisy.addFrame(img, noisyWall(0.005, k));
			noisyBlocks.addFrame(img2, noisyWall(0.005, k));
		}
		EXPECT_NEAR(noisy.result().colourNoise, 2.0, 0.1);
		EXPECT_NEAR(noisyBlocks.result().colourNoise, 2.0, 0.4);
	}
	// The wall's patches measure the noise: 5 mm at 2.1-2.3 m (bin 2.0-2.5 m), k = 5 mm / 2.2^2.
	const auto w = flat.result();
	EXPECT_NEAR(w.validDepthShare, 1.0, 1e-9);
	EXPECT_GT(w.noise[3].patches, 10000u);
	EXPECT_NEAR(w.noise[3].medianResidual, 0.005, 0.0005);
	EXPECT_NEAR(w.noiseK, 0.005 / (2.25 * 2.25), 0.0002);
	for (std::size_t b = 0; b < w.noise.size(); b++)
	{
		if (b != 3)
		{
			EXPECT_EQ(w.noise[b].patches, 0u) << b;
		}
	}
}

TEST(SensorStatistics, FlyingPixelsBetweenAPersonAndTheWallAreCounted)
{
	// A person at 1.5 m before a wall at 3 m; along its left edge one pixel per row lies half way
	// (the mixed return of a structured-light sensor).
	cv::Mat d(480, 640, CV_32F, cv::Scalar(3.0f));
	d(cv::Rect(300, 100, 100, 300)).setTo(1.5f);
	for (int y = 100; y < 400; y++) d.at<float>(y, 299) = 2.25f;
	CSensorStatistics s;
	s.addFrame(cv::Mat(480, 640, CV_8U, cv::Scalar(128)), d);
	EXPECT_NEAR(s.result().flyingPixelShare, 300.0 / (640 * 480), 1e-9);
}

TEST(SensorStatistics, DarkSurfacesAreWhereTheCorrelationWindowIsDark)
{
	// One definition for the statistics and the simulator's real sensor: the 9 x 9 window's mean
	// under 60 grey levels. A 40-grey square on a 200-grey wall: dark inside, light outside, and the
	// window decides along the square's edge.
	cv::Mat g(100, 100, CV_8U, cv::Scalar(200));
	g(cv::Rect(30, 30, 40, 40)).setTo(40);
	const cv::Mat d = CSensorStatistics::darkSurfaces(g);
	ASSERT_EQ(d.type(), CV_8U);
	EXPECT_EQ(d.at<uchar>(50, 50), 255);
	EXPECT_EQ(d.at<uchar>(10, 10), 0);
	EXPECT_EQ(d.at<uchar>(50, 33), 255) << "3 px inside: one light column of 9, mean 58";
	EXPECT_EQ(d.at<uchar>(50, 30), 0) << "on the edge: 4 of 9 columns light, mean 111";
	EXPECT_EQ(cv::countNonZero(d(cv::Rect(30, 30, 40, 40))), cv::countNonZero(d)) << "nothing dark outside the square";
	EXPECT_GT(cv::countNonZero(d), 30 * 30);
	EXPECT_LT(cv::countNonZero(d), 34 * 34) << "the square's rim and corners are not: their windows reach the wall";
}
