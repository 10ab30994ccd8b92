// Reading TUM RGB-D folders directly: exact depth, pairing, camera, and every kind of bad folder.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "TestUtils.h"
#include "mrpt_yesslam/io/CPrefetchingSource.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
// Asserts that an observation holds exactly the frame's pixels and raw depth.
void expectSameFrame(const mrpt::obs::CObservation3DRangeScan& obs, const SyntheticFrame& f)
{
	ASSERT_EQ(obs.rangeImage.rows(), f.depth.rows);
	ASSERT_EQ(obs.rangeImage.cols(), f.depth.cols);
	int bad = 0;
	for (int y = 0; y < f.depth.rows; y++)
		for (int x = 0; x < f.depth.cols; x++) bad += obs.rangeImage(y, x) != f.depth.at<uint16_t>(y, x);
	EXPECT_EQ(bad, 0) << "raw depth values changed";
	EXPECT_FLOAT_EQ(obs.rangeUnits, 0.0002f);
	const cv::Mat img = obs.intensityImage.asCvMatRef();
	ASSERT_EQ(img.type(), CV_8UC3);
	EXPECT_EQ(cv::norm(img, f.bgr, cv::NORM_INF), 0.0) << "colour pixels changed";
	EXPECT_NEAR(observationTime(obs), f.tRgb, 1e-6);
}
}  // namespace

TEST(TumFolder, ReadsFramesWithExactDepth)
{
	TempDir d("tum");
	const auto frames = makeSyntheticFrames(5);
	writeTumFolder(d.path(), frames);
	CTumFolderSource src(d.path());
	EXPECT_EQ(src.sizeHint(), 5u);
	EXPECT_EQ(src.skipped(), 0u);
	for (const auto& f : frames)
	{
		auto obs = src.next();
		ASSERT_TRUE(obs);
		expectSameFrame(*obs, f);
		EXPECT_DOUBLE_EQ(obs->cameraParamsIntensity.fx(), 535.4);
		// Depth in metres through MRPT's own conversion.
		EXPECT_NEAR(obs->rangeImage(10, 20) * obs->rangeUnits, (5001 + 7 * 20 + 3 * 10 + (&f - &frames[0])) / 5000.0,
					1e-6);
	}
	EXPECT_FALSE(src.next());
}

TEST(TumFolder, PairsLikeAssociatePyAndCountsSkipped)
{
	TempDir d("tum");
	auto frames = makeSyntheticFrames(4);
	frames[2].tDepth = frames[2].tRgb + 0.025;  // 25 ms from its rgb image, closer to the next one
	writeTumFolder(d.path(), frames);
	CTumFolderSource src(d.path());
	EXPECT_EQ(src.sizeHint(), 3u);
	EXPECT_EQ(src.skipped(), 1u);
	EXPECT_NEAR(src.frames()[2].tRgb, frames[3].tRgb, 1e-9);
}

TEST(TumFolder, TellsWhenEachDepthImageWasTakenAlsoThroughAPrefetcher)
{
	// Real fr1/desk stamps (TUM RGB-D, CC BY 4.0; via slambook, MIT): each depth image 9-15 ms after
	// its colour image. SLAM moves keypoint depth by that much camera motion ([Tracking] depthMoment).
	const std::string folder = sharedFile("data/tum_fr1_desk_9frames");
	auto src = std::make_unique<CTumFolderSource>(folder);
	const std::vector<TTumFrame> frames = src->frames();
	ASSERT_EQ(frames.size(), 9u);
	CPrefetchingSource ahead(std::move(src), 3);
	for (const auto& f : frames)
	{
		auto obs = ahead.next();  // the reader thread runs on meanwhile
		ASSERT_TRUE(obs);
		const auto td = ahead.depthTime(observationTime(*obs));
		ASSERT_TRUE(td) << std::fixed << f.tRgb;
		EXPECT_NEAR(*td, f.tDepth, 1e-6);
		EXPECT_GT(*td - f.tRgb, 0.009);
		EXPECT_LT(*td - f.tRgb, 0.015);
	}
	EXPECT_FALSE(ahead.depthTime(frames[0].tRgb + 0.01)) << "no colour image has that stamp";
}

TEST(TumFolder, RealFr1DeskFrames)
{
	// 9 real TUM fr1/desk frames (TUM RGB-D, CC BY 4.0; via slambook, MIT): calibration.txt beside them.
	const std::string folder = sharedFile("data/tum_fr1_desk_9frames");
	CTumFolderSource src(folder);
	EXPECT_EQ(src.sizeHint(), 9u);
	EXPECT_DOUBLE_EQ(src.camera().intrinsics.fx(), 517.3);
	const cv::Mat raw = cv::imread(folder + "/depth/1305031453.374112.png", cv::IMREAD_UNCHANGED);
	ASSERT_EQ(raw.type(), CV_16UC1);
	auto obs = src.next();
	ASSERT_TRUE(obs);
	int bad = 0, valid = 0;
	uint16_t lo = 65535, hi = 0;
	for (int y = 0; y < raw.rows; y++)
		for (int x = 0; x < raw.cols; x++)
		{
			const uint16_t v = obs->rangeImage(y, x);
			bad += v != raw.at<uint16_t>(y, x);
			if (v)
			{
				valid++;
				lo = std::min(lo, v);
				hi = std::max(hi, v);
			}
		}
	EXPECT_EQ(bad, 0);
	EXPECT_GT(lo, 3000);   // about 0.7 m: a desk seen from a hand-held Kinect
	EXPECT_LT(hi, 13000);  // about 2.6 m
	EXPECT_GT(valid, 640 * 480 * 3 / 4);
	int n = 1;
	while (src.next()) n++;
	EXPECT_EQ(n, 9);
}

TEST(TumFolder, CameraFromFolderName)
{
	TempDir d("tum");
	const std::string folder = d / "rgbd_dataset_freiburg2_desk";
	// 640x480 frames so that the fr2 calibration fits.
	writeTumFolder(folder, makeSyntheticFrames(1, 640, 480), true, false);
	CTumFolderSource src(folder);
	EXPECT_EQ(src.camera().name, "fr2");
	auto obs = src.next();
	ASSERT_TRUE(obs);
	EXPECT_DOUBLE_EQ(obs->cameraParamsIntensity.fx(), 520.9);
	EXPECT_DOUBLE_EQ(obs->cameraParamsIntensity.dist[0], 0.2312);
	// An explicit name wins over the folder name.
	CInputSource::TOptions o;
	o.camera = "fr1";
	EXPECT_EQ(CTumFolderSource(folder, o).camera().name, "fr1");
	// 64x48 frames do not fit a 640x480 camera: said clearly.
	const std::string small = d / "rgbd_dataset_freiburg3_small";
	writeTumFolder(small, makeSyntheticFrames(1), true, false);
	CTumFolderSource s2(small);
	expectInputError([&] { s2.next(); }, {"image is 64x48 but camera 'fr3' is 640x480"});
}

TEST(TumFolder, BadFolders)
{
	TempDir d("tumbad");
	expectInputError([&] { CTumFolderSource(d / "missing"); }, {"missing", "folder not found"});
	expectInputError([&] { CTumFolderSource src(d.path()); }, {"rgb.txt", "file not found"});

	// rgb.txt with no depth within 0.02 s.
	{
		const std::string f = d / "nodepth";
		auto frames = makeSyntheticFrames(2);
		for (auto& fr : frames) fr.tDepth += 10.0;
		writeTumFolder(f, frames);
		expectInputError([&] { CTumFolderSource src(f); }, {"rgb.txt", "no image has a depth.txt entry within"});
	}
	// Stamps going backwards.
	{
		const std::string f = d / "order";
		writeTumFolder(f, makeSyntheticFrames(2));
		writeText(f + "/rgb.txt", "2.0 rgb/a.png\n1.0 rgb/b.png\n");
		expectInputError([&] { CTumFolderSource src(f); }, {"rgb.txt", "line 2", "earlier"});
	}
	// Malformed list line.
	{
		const std::string f = d / "malformed";
		writeTumFolder(f, makeSyntheticFrames(2));
		writeText(f + "/depth.txt", "# x\nabc depth/a.png\n");
		expectInputError([&] { CTumFolderSource src(f); }, {"depth.txt", "line 2", "'abc'"});
	}
	auto firstFrameError = [&](const std::string& tag, const std::function<void(const std::string&)>& damage,
							   const std::vector<std::string>& fragments)
	{
		const std::string f = d / tag;
		writeTumFolder(f, makeSyntheticFrames(2));
		damage(f);
		CTumFolderSource src(f);
		expectInputError([&] { src.next(); }, fragments);
	};
	auto firstDepth = [](const std::string& f) { return f + "/depth/1000.004000.png"; };
	auto firstRgb = [](const std::string& f) { return f + "/rgb/1000.000000.png"; };
	firstFrameError("missingpng", [&](const std::string& f) { fs::remove(firstRgb(f)); },
					{"1000.000000.png", "not found"});
	firstFrameError("truncated", [&](const std::string& f) { fs::resize_file(firstDepth(f), 40); },
					{"1000.004000.png", "cannot decode"});
	firstFrameError("notimage", [&](const std::string& f) { writeText(firstRgb(f), "this is not a PNG"); },
					{"1000.000000.png", "cannot decode"});
	firstFrameError("eightbit",
					[&](const std::string& f)
					{
						cv::Mat m(48, 64, CV_8UC1, cv::Scalar(100));
						cv::imwrite(firstDepth(f), m);
					},
					{"1000.004000.png", "8-bit"});
	firstFrameError("wrongsize",
					[&](const std::string& f)
					{
						cv::Mat m(24, 32, CV_16UC1, cv::Scalar(5000));
						cv::imwrite(firstDepth(f), m);
					},
					{"1000.004000.png", "32x24", "64x48"});
	firstFrameError("floatdepth",
					[&](const std::string& f)
					{
						// Depth in metres as a float image (a common mistake when exporting from other tools).
						cv::Mat m(48, 64, CV_32FC1, cv::Scalar(1.5f));
						const std::string tif = f + "/depth/1000.004000.tiff";
						cv::imwrite(tif, m);
						writeText(f + "/depth.txt",
								  "1000.004000 depth/1000.004000.tiff\n1000.037333 depth/1000.037333.png\n");
					},
					{"floating-point"});
}
