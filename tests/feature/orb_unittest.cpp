// ORB extraction on a real TUM fr1/desk frame (CC BY 4.0): budget, even spread, depth, mask.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "TestUtils.h"
#include "mrpt_yesslam/feature/COrbExtractor.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

namespace
{
// Share of the keypoints that fall into the fullest of 8x6 image cells, and cells with none.
std::pair<double, int> spread(const std::vector<cv::KeyPoint>& kps, cv::Size img)
{
	std::vector<int> cells(48, 0);
	for (const auto& k : kps)
		cells[static_cast<std::size_t>(std::min(5, static_cast<int>(k.pt.y * 6 / img.height)) * 8 +
									   std::min(7, static_cast<int>(k.pt.x * 8 / img.width)))]++;
	return {static_cast<double>(*std::max_element(cells.begin(), cells.end())) / static_cast<double>(kps.size()),
			static_cast<int>(std::count(cells.begin(), cells.end(), 0))};
}
}  // namespace

TEST(OrbExtractor, BudgetSpreadAndDepthOnARealFrame)
{
	const std::string dir = sharedFile("data/tum_fr1_desk_9frames");
	const cv::Mat img = cv::imread(dir + "/rgb/1305031453.359684.png", cv::IMREAD_COLOR);
	const cv::Mat raw = cv::imread(dir + "/depth/1305031453.374112.png", cv::IMREAD_UNCHANGED);
	ASSERT_FALSE(img.empty());
	cv::Mat depth;
	raw.convertTo(depth, CV_32F, 1.0 / 5000);
	COrbExtractor ex;
	const auto f = ex.extract(img, depth);
	EXPECT_GE(f.keypoints.size(), 900u);
	EXPECT_LE(f.keypoints.size(), 1000u);
	EXPECT_EQ(f.descriptors.rows, static_cast<int>(f.keypoints.size()));
	EXPECT_EQ(f.descriptors.cols, 32);
	EXPECT_EQ(f.numStatic(), f.keypoints.size());
	// Spread: no cell holds more than 6% of the features, and plain OpenCV ORB clusters more.
	const auto ours = spread(f.keypoints, img.size());
	std::vector<cv::KeyPoint> plain;
	cv::ORB::create(1000)->detect(img, plain);
	const auto theirs = spread(plain, img.size());
	EXPECT_LT(ours.first, 0.08);
	EXPECT_LT(ours.first, 0.75 * theirs.first) << "fullest cell: ours " << ours.first << ", plain ORB " << theirs.first;
	EXPECT_LE(ours.second, theirs.second) << "empty cells: ours " << ours.second << ", plain ORB " << theirs.second;
	// Several pyramid levels are used.
	std::set<int> levels;
	for (const auto& k : f.keypoints) levels.insert(k.octave);
	EXPECT_GE(levels.size(), 5u);
	// Depth is the registered depth at the keypoint (between its four pixels), kept only where the
	// 5x5 neighbourhood of its pixel is one surface (3% + 1 cm): corners on depth edges get none.
	// Most desk keypoints keep theirs.
	std::size_t withDepth = 0, onEdges = 0;
	for (std::size_t i = 0; i < f.keypoints.size(); i++)
	{
		const cv::Point p(static_cast<int>(std::lround(f.keypoints[i].pt.x)),
						  static_cast<int>(std::lround(f.keypoints[i].pt.y)));
		if (p.x < 2 || p.y < 2 || p.x >= depth.cols - 2 || p.y >= depth.rows - 2) continue;
		const float z = depth.at<float>(p);
		double lo = 1e9, hi = 0;
		for (int dy = -2; dy <= 2; dy++)
			for (int dx = -2; dx <= 2; dx++)
			{
				const float w = depth.at<float>(p.y + dy, p.x + dx);
				lo = std::min(lo, static_cast<double>(w));
				hi = std::max(hi, static_cast<double>(w));
			}
		const bool smooth = z > 0 && lo > 0 && hi - z <= 0.03 * z + 0.01 && z - lo <= 0.03 * z + 0.01;
		if (smooth)
		{
			EXPECT_GE(f.depth[i], lo - 1e-6);
			EXPECT_LE(f.depth[i], hi + 1e-6);
		}
		else
			EXPECT_EQ(f.depth[i], 0.f);
		withDepth += f.depth[i] > 0;
		onEdges += z > 0 && !smooth;
	}
	EXPECT_GT(withDepth, f.keypoints.size() / 2) << onEdges << " on depth edges";
	EXPECT_GT(onEdges, 0u);
}

TEST(OrbExtractor, ItsCornersAndOrientationsAreThoseOfOpenCVsOrb)
{
	// The extractor detects on its own (issue 41: OpenCV's ORB oriented all four thousand
	// candidates and built a bordered pyramid, twice with compute) but must find what OpenCV's ORB
	// with the same settings finds: the same corners at the same levels, steered the same way, so
	// the descriptors match those of the map and the vocabulary.
	const std::string dir = sharedFile("data/tum_fr1_desk_9frames");
	const cv::Mat img = cv::imread(dir + "/rgb/1305031453.359684.png", cv::IMREAD_COLOR);
	ASSERT_FALSE(img.empty());
	cv::Mat grey;
	cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
	const COrbExtractor::TOptions o;
	const auto f = COrbExtractor(o).extract(img);
	auto orb = cv::ORB::create(o.numFeatures * 4, static_cast<float>(o.scaleFactor), o.numLevels, 19, 0, 2,
							   cv::ORB::FAST_SCORE, 31, o.fastThreshold);
	std::vector<cv::KeyPoint> theirs;
	cv::Mat theirDescriptors;
	orb->detectAndCompute(grey, cv::noArray(), theirs, theirDescriptors);
	std::size_t same = 0, steered = 0, close = 0;
	for (std::size_t i = 0; i < f.keypoints.size(); i++)
	{
		const auto& k = f.keypoints[i];
		// Undo the extractor's pixel-centre correction of the level's coordinates.
		const float off = 0.5f * (static_cast<float>(std::pow(o.scaleFactor, k.octave)) - 1.f);
		const cv::Point2f p(k.pt.x - off, k.pt.y - off);
		for (std::size_t j = 0; j < theirs.size(); j++)
		{
			const auto& t = theirs[j];
			if (t.octave != k.octave || cv::norm(t.pt - p) > 0.01) continue;
			same++;
			const float d = std::abs(t.angle - k.angle);
			steered += std::min(d, 360.f - d) < 1.f;
			close += cv::norm(f.descriptors.row(static_cast<int>(i)), theirDescriptors.row(static_cast<int>(j)),
							  cv::NORM_HAMMING) <= 8;
			break;
		}
	}
	const auto n = f.keypoints.size();
	ASSERT_GE(n, 900u);
	EXPECT_GE(same, n * 97 / 100) << "keypoints OpenCV's ORB also finds";
	EXPECT_GE(steered, same * 97 / 100) << "of those, oriented within a degree";
	EXPECT_GE(close, same * 95 / 100) << "of those, descriptors within 8 bits";
}

TEST(OrbExtractor, ItsDescriptorsAreThoseOpenCVsOrbComputesForTheSameKeypoints)
{
	// The extractor describes each level's keypoints on its own pyramid level (issue 41: OpenCV's
	// compute() rebuilt the whole pyramid, a third of its time); the map, the vocabulary and loop
	// closing need the very descriptors OpenCV's ORB gives the same oriented keypoints.
	const std::string dir = sharedFile("data/tum_fr1_desk_9frames");
	for (const char* name : {"1305031453.359684.png", "1305031453.391690.png"})
	{
		const cv::Mat img = cv::imread(dir + "/rgb/" + name, cv::IMREAD_COLOR);
		ASSERT_FALSE(img.empty()) << name;
		cv::Mat grey;
		cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
		const COrbExtractor::TOptions o;
		const auto f = COrbExtractor(o).extract(img);
		std::vector<cv::KeyPoint> kps = f.keypoints;
		for (auto& k : kps)
		{
			// As OpenCV reported them: before the extractor's pixel-centre correction.
			const float off = 0.5f * (static_cast<float>(std::pow(o.scaleFactor, k.octave)) - 1.f);
			k.pt -= cv::Point2f(off, off);
		}
		auto orb = cv::ORB::create(o.numFeatures, static_cast<float>(o.scaleFactor), o.numLevels, 19, 0, 2,
								   cv::ORB::FAST_SCORE, 31, o.fastThreshold);
		const std::size_t n = kps.size();
		cv::Mat theirs;
		orb->compute(grey, kps, theirs);
		ASSERT_EQ(kps.size(), n) << "OpenCV kept every keypoint";
		ASSERT_EQ(theirs.rows, f.descriptors.rows);
		// compute() lists its keypoints level by level, as the extractor already does: row i is keypoint i.
		std::size_t same = 0;
		for (std::size_t i = 0; i < n; i++)
		{
			const float off = 0.5f * (static_cast<float>(std::pow(o.scaleFactor, f.keypoints[i].octave)) - 1.f);
			ASSERT_LT(cv::norm(kps[i].pt + cv::Point2f(off, off) - f.keypoints[i].pt), 1e-3) << "keypoint " << i;
			same += cv::norm(f.descriptors.row(static_cast<int>(i)), theirs.row(static_cast<int>(i)),
							 cv::NORM_HAMMING) == 0;
		}
		EXPECT_EQ(same, n) << name << ": descriptors equal to the bit";
	}
}

TEST(OrbExtractor, KeypointDepthIsTheSurfacesAtTheKeypointNotAtItsNearestPixel)
{
	// A wall seen at a slant: depth grows 1 cm a pixel across the image (a floor 3-4 m away does
	// that). Keypoints of the coarser pyramid levels sit between pixels; the nearest pixel's depth
	// would be up to 5 mm off the surface along the keypoint's ray (the point then lies off the wall).
	cv::Mat img(480, 640, CV_8UC3);
	cv::RNG rng(7);
	for (int y = 0; y < img.rows; y += 8)
		for (int x = 0; x < img.cols; x += 8) img(cv::Rect(x, y, 8, 8)).setTo(cv::Scalar::all(rng.uniform(0, 256)));
	cv::Mat depth(480, 640, CV_32F);
	for (int y = 0; y < depth.rows; y++)
		for (int x = 0; x < depth.cols; x++) depth.at<float>(y, x) = 1.5f + 0.01f * static_cast<float>(x);
	const auto f = COrbExtractor().extract(img, depth);
	std::size_t between = 0, withDepth = 0;
	double worst = 0;
	for (std::size_t i = 0; i < f.keypoints.size(); i++)
	{
		if (!(f.depth[i] > 0)) continue;
		withDepth++;
		const double x = f.keypoints[i].pt.x;
		between += std::abs(x - std::round(x)) > 0.2;
		worst = std::max(worst, std::abs(f.depth[i] - (1.5 + 0.01 * x)));
	}
	EXPECT_GT(withDepth, f.keypoints.size() * 9 / 10);
	EXPECT_GT(between, withDepth / 5) << "keypoints between pixels";
	EXPECT_LT(worst, 1e-4) << "largest depth error along the keypoint's ray, m";
}

TEST(OrbExtractor, DynamicMaskFlagsOrExcludes)
{
	const cv::Mat img = cv::imread(sharedFile("data/tum_fr1_desk_9frames/rgb/1305031453.359684.png"), cv::IMREAD_COLOR);
	cv::Mat mask = cv::Mat::zeros(img.size(), CV_8U);
	mask(cv::Rect(0, 0, 320, 480)).setTo(255);
	COrbExtractor::TOptions o;
	const auto flagged = COrbExtractor(o).extract(img, {}, mask);
	std::size_t left = 0;
	for (std::size_t i = 0; i < flagged.keypoints.size(); i++)
	{
		const bool inMask = std::lround(flagged.keypoints[i].pt.x) < 320;
		EXPECT_EQ(flagged.dynamic[i], inMask);
		left += inMask;
	}
	EXPECT_GT(left, 200u);
	EXPECT_EQ(flagged.numStatic(), flagged.keypoints.size() - left);
	// Excluding the mask gives the whole budget to the static half.
	o.excludeMasked = true;
	const auto excluded = COrbExtractor(o).extract(img, {}, mask);
	for (const auto& k : excluded.keypoints) EXPECT_GE(std::lround(k.pt.x), 320 - 1);
	EXPECT_GT(excluded.keypoints.size(), flagged.numStatic() * 3 / 2);
}

TEST(OrbExtractor, BadOptions)
{
	COrbExtractor::TOptions o;
	o.scaleFactor = 1.0;
	expectInputError([&] { COrbExtractor e(o); }, {"scaleFactor"});
}
