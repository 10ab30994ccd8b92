// Rawlogs: TUM -> rawlog -> frames round trip (inline and external images), both rawlog formats,
// and truncated or corrupt files.
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <filesystem>
#include <fstream>

#include "TestUtils.h"
#include "mrpt_yesslam/io/CRawlogSource.h"
#include "mrpt_yesslam/io/CRawlogWriter.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/io/TumToRawlog.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
void expectFramesEqual(CInputSource& src, const std::vector<SyntheticFrame>& frames)
{
	for (const auto& f : frames)
	{
		auto obs = src.next();
		ASSERT_TRUE(obs);
		int bad = 0;
		for (int y = 0; y < f.depth.rows; y++)
			for (int x = 0; x < f.depth.cols; x++) bad += obs->rangeImage(y, x) != f.depth.at<uint16_t>(y, x);
		EXPECT_EQ(bad, 0);
		EXPECT_FLOAT_EQ(obs->rangeUnits, 0.0002f);
		EXPECT_EQ(cv::norm(obs->intensityImage.asCvMatRef(), f.bgr, cv::NORM_INF), 0.0);
		EXPECT_NEAR(observationTime(*obs), f.tRgb, 1e-6);
		EXPECT_DOUBLE_EQ(obs->cameraParamsIntensity.fy(), 539.2);
	}
	EXPECT_FALSE(src.next());
}
}  // namespace

TEST(Rawlog, TumToRawlogRoundTripInline)
{
	TempDir d("rawlog");
	const auto frames = makeSyntheticFrames(6);
	writeTumFolder(d / "seq", frames);
	TTumToRawlogOptions o;
	o.folder = d / "seq";
	o.output = d / "seq.rawlog";
	std::size_t calls = 0;
	const auto sum = convertTumToRawlog(o,
										[&](std::size_t done, std::size_t total)
										{
											calls++;
											EXPECT_EQ(total, 6u);
											EXPECT_EQ(done, calls);
										});
	EXPECT_EQ(calls, 6u);
	EXPECT_EQ(sum.frames, 6u);
	EXPECT_EQ(sum.skipped, 0u);
	EXPECT_NEAR(sum.tLast - sum.tFirst, 5 / 30.0, 1e-6);
	EXPECT_EQ(sum.bytes, fs::file_size(o.output));
	// Ground truth copied beside, unchanged, and found by findGroundTruthFor.
	ASSERT_EQ(sum.groundTruth, (d / "seq_groundtruth.txt"));
	EXPECT_EQ(readTumTrajectory(sum.groundTruth).size(), 6u);
	EXPECT_EQ(findGroundTruthFor(o.output), sum.groundTruth);
	CRawlogSource src(o.output);
	expectFramesEqual(src, frames);
	// The factory picks the right source for files and folders.
	auto src2 = openInputSource(o.output);
	expectFramesEqual(*src2, frames);
	auto src3 = openInputSource(o.folder);
	expectFramesEqual(*src3, frames);
}

TEST(Rawlog, TumToRawlogExternalImages)
{
	TempDir d("rawlog");
	const auto frames = makeSyntheticFrames(3);
	writeTumFolder(d / "seq", frames, false);
	TTumToRawlogOptions o;
	o.folder = d / "seq";
	o.output = d / "ext.rawlog";
	o.externalImages = true;
	const auto sum = convertTumToRawlog(o);
	EXPECT_TRUE(sum.groundTruth.empty());
	EXPECT_TRUE(fs::is_directory(d / "ext_Images"));
	EXPECT_EQ(std::distance(fs::directory_iterator(d / "ext_Images"), fs::directory_iterator()), 3);
	// Inline images would make the rawlog far bigger than the depth alone.
	TTumToRawlogOptions inl = o;
	inl.externalImages = false;
	inl.output = d / "inline.rawlog";
	convertTumToRawlog(inl);
	EXPECT_LT(fs::file_size(o.output), fs::file_size(inl.output));
	CRawlogSource src(o.output);
	expectFramesEqual(src, frames);

	// A missing external image is reported with the frame and folder.
	fs::remove(d / "ext_Images/1000.000000.png");
	CRawlogSource src2(o.output);
	expectInputError([&] { src2.next(); }, {"ext.rawlog: frame 1", "cannot load external data", "ext_Images"});
	// A missing images folder is named in full (issue 18 item 5).
	fs::remove_all(d / "ext_Images");
	CRawlogSource src3(o.output);
	expectInputError(
		[&] { src3.next(); },
		{"ext.rawlog: frame 1",
		 "the images folder '" + fs::absolute(d / "ext_Images").lexically_normal().string() + "' does not exist"});
}

TEST(Rawlog, ActionObservationFormatAndOtherSensors)
{
	TempDir d("rawlog");
	const auto frames = makeSyntheticFrames(3);
	TRgbdCamera cam = tumCameraByName("fr3");
	cam.intrinsics.ncols = 64;
	cam.intrinsics.nrows = 48;
	const std::string path = d / "ao.rawlog";
	{
		mrpt::io::CFileGZOutputStream f(path);
		auto arch = mrpt::serialization::archiveFrom(f);
		for (const auto& fr : frames)
		{
			mrpt::obs::CActionCollection acts;
			mrpt::obs::CSensoryFrame sf;
			sf.insert(makeRgbdObservation(fr.tRgb, fr.bgr, fr.depth, cam));
			auto odo = mrpt::obs::CObservationOdometry::Create();
			sf.insert(odo);  // not an RGB-D frame: skipped
			arch << acts << sf;
		}
	}
	CRawlogSource src(path);
	expectFramesEqual(src, frames);
	EXPECT_EQ(src.skipped(), 3u);

	// The observation-only writer, and a sensor-label filter.
	const std::string path2 = d / "obs.rawlog";
	{
		CRawlogWriter w(path2);
		for (const auto& fr : frames) w.write(*makeRgbdObservation(fr.tRgb, fr.bgr, fr.depth, cam, "KINECT"));
		EXPECT_FALSE(fs::exists(path2)) << "the file appears only on commit";
		w.commit();
	}
	CInputSource::TOptions o;
	o.sensorLabel = "OTHER";
	CRawlogSource filtered(path2, o);
	expectInputError([&] { filtered.next(); }, {"obs.rawlog", "no RGB-D frames", "sensor label 'OTHER'", "3 entries"});
	EXPECT_EQ(filtered.skipped(), 3u);
}

TEST(Rawlog, UncommittedWriterLeavesNothing)
{
	TempDir d("rawlog");
	{
		CRawlogWriter w(d / "x.rawlog");
		w.write(*makeRgbdObservation(1.0, makeSyntheticFrames(1)[0].bgr, makeSyntheticFrames(1)[0].depth,
									 tumCameraByName("fr3")));
	}
	EXPECT_TRUE(fs::is_empty(d.path()));
}

TEST(Rawlog, CorruptAndTruncatedFiles)
{
	TempDir d("rawlog");
	const auto frames = makeSyntheticFrames(4);
	writeTumFolder(d / "seq", frames);
	TTumToRawlogOptions o;
	o.folder = d / "seq";
	o.output = d / "good.rawlog";
	convertTumToRawlog(o);

	expectInputError([&] { CRawlogSource s(d / "none.rawlog"); }, {"none.rawlog", "file not found"});
	writeText(d / "empty.rawlog", "");
	expectInputError([&] { CRawlogSource s(d / "empty.rawlog"); }, {"empty.rawlog", "empty"});

	// Reading to the end must raise our error, never crash, whatever the damage.
	auto readAll = [](const std::string& p)
	{
		CRawlogSource s(p);
		while (s.next())
		{
		}
	};
	// Uncompressed copy truncated in the middle of the second frame.
	{
		CRawlogSource s(o.output);
		CRawlogWriter w(d / "plain.rawlog", 0);
		while (auto obs = s.next()) w.write(*obs);
		w.commit();
		const auto size = fs::file_size(d / "plain.rawlog");
		fs::copy_file(d / "plain.rawlog", d / "cut.rawlog");
		fs::resize_file(d / "cut.rawlog", size * 3 / 8);
		expectInputError([&] { readAll(d / "cut.rawlog"); }, {"cut.rawlog", "corrupt or truncated rawlog at entry 2"});
	}
	// Garbage bytes.
	{
		std::string junk(5000, '\0');
		for (std::size_t i = 0; i < junk.size(); i++) junk[i] = static_cast<char>((i * 7919 + 13) & 255);
		writeText(d / "junk.rawlog", junk);
		expectInputError([&] { readAll(d / "junk.rawlog"); },
						 {"junk.rawlog", "corrupt or truncated rawlog at entry 1"});
	}
	// A gz file cut short.
	{
		fs::copy_file(o.output, d / "gzcut.rawlog");
		fs::resize_file(d / "gzcut.rawlog", fs::file_size(o.output) / 2);
		expectInputError([&] { readAll(d / "gzcut.rawlog"); }, {"gzcut.rawlog", "corrupt or truncated rawlog"});
	}
}
