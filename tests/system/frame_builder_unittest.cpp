// The frame builder: colours come from the raw (distorted) keypoint positions, keypoints end up
// undistorted by the one camera model, and asynchronous detection gives the same frame as
// synchronous detection.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "TestUtils.h"
#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/geometry/CPinholeCamera.h"
#include "mrpt_yesslam/system/CFrameBuilder.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

namespace
{
// Random coloured blocks (every block a different colour, so that a colour sampled a few pixels
// off lands on another block near corners) and a flat depth of 2 m.
void texturedScene(cv::Mat& bgr, cv::Mat& depth)
{
	std::mt19937 rng(11);
	std::uniform_int_distribution<int> c(0, 255);
	bgr = cv::Mat(480, 640, CV_8UC3);
	for (int y = 0; y < 480; y += 12)
		for (int x = 0; x < 640; x += 12)
			cv::rectangle(bgr, cv::Rect(x, y, 12, 12), cv::Scalar(c(rng), c(rng), c(rng)), cv::FILLED);
	depth = cv::Mat(480, 640, CV_32F, cv::Scalar(2.0f));
}

CFrameBuilder builder(bool async)
{
	return CFrameBuilder(nullptr, CDynamicObjectMasker::TOptions(), COrbExtractor::TOptions(), true, async);
}
}  // namespace

// Review finding: colours were sampled at the undistorted keypoint position in the distorted image.
TEST(FrameBuilder, ColoursComeFromTheRawKeypointsAndKeypointsAreUndistorted)
{
	cv::Mat bgr, depth;
	texturedScene(bgr, depth);
	mrpt::img::TCamera K = fr3Camera();
	auto b = builder(false);
	const auto plain = b.build(bgr, depth, 0.0, K, 0);
	K.dist[0] = 0.25;  // strong barrel distortion: keypoints near the borders move by many pixels
	K.dist[1] = -0.5;
	const auto distorted = b.build(bgr, depth, 0.0, K, 1);
	ASSERT_GT(plain->size(), 200u);
	ASSERT_EQ(plain->size(), distorted->size());  // the same raw keypoints
	std::size_t moved = 0;
	for (std::size_t i = 0; i < plain->size(); i++)
	{
		// Same colour as without distortion: sampled at the raw position.
		EXPECT_EQ(distorted->colors[i], plain->colors[i]) << i;
		const auto& raw = plain->features.keypoints[i].pt;
		const auto& und = distorted->features.keypoints[i].pt;
		if (cv::norm(raw - und) > 3) moved++;
		// And the undistorted position maps back to the raw one through the distortion model.
		const double x = (und.x - K.cx()) / K.fx(), y = (und.y - K.cy()) / K.fy(), r2 = x * x + y * y;
		const double g = 1 + K.dist[0] * r2 + K.dist[1] * r2 * r2;
		EXPECT_NEAR(K.fx() * x * g + K.cx(), raw.x, 0.05);
		EXPECT_NEAR(K.fy() * y * g + K.cy(), raw.y, 0.05);
	}
	EXPECT_GT(moved, plain->size() / 4);
}

TEST(FrameBuilder, AsynchronousDetectionGivesTheSameFrame)
{
	cv::Mat bgr, depth;
	texturedScene(bgr, depth);
	// A person box from a detections file (the real file detector), masking part of the image.
	TempDir d("builder_async");
	writeText(d / "det.txt", "0.000000 0 0.9 100 80 160 300\n");
	CObjectDetector::TOptions det;
	det.backend = "file";
	det.file = d / "det.txt";
	CDynamicObjectMasker::TOptions mo;
	mo.method = "box";
	CFrameBuilder sync(createObjectDetector(det), mo, COrbExtractor::TOptions(), true, false);
	CFrameBuilder async(createObjectDetector(det), mo, COrbExtractor::TOptions(), true, true);
	const auto a = sync.build(bgr, depth, 0.0, fr3Camera(), 0), b = async.build(bgr, depth, 0.0, fr3Camera(), 0);
	ASSERT_EQ(a->detections.size(), 1u);
	ASSERT_EQ(b->detections.size(), 1u);
	ASSERT_EQ(a->size(), b->size());
	EXPECT_EQ(a->features.dynamic, b->features.dynamic);
	EXPECT_GT(a->size() - a->features.numStatic(), 10u);  // the box did mask keypoints
	EXPECT_EQ(cv::norm(a->features.descriptors, b->features.descriptors, cv::NORM_HAMMING), 0);
}
