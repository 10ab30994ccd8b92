// Camera models: TUM names, names found in folder paths, camera files and their errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "TestUtils.h"
#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/io/COpenNI2Source.h"
#include "mrpt_yesslam/io/RgbdCamera.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

TEST(Camera, TumNamesGivePublishedCalibrations)
{
	const auto fr1 = tumCameraByName("freiburg1");
	EXPECT_DOUBLE_EQ(fr1.intrinsics.fx(), 517.3);
	EXPECT_DOUBLE_EQ(fr1.intrinsics.cy(), 255.3);
	EXPECT_DOUBLE_EQ(fr1.intrinsics.dist[0], 0.2624);
	EXPECT_DOUBLE_EQ(fr1.intrinsics.dist[4], 1.1633);
	const auto fr2 = tumCameraByName("FR2");
	EXPECT_DOUBLE_EQ(fr2.intrinsics.fy(), 521.0);
	EXPECT_DOUBLE_EQ(fr2.intrinsics.dist[1], -0.7849);
	const auto fr3 = tumCameraByName("fr3");
	EXPECT_DOUBLE_EQ(fr3.intrinsics.fx(), 535.4);
	EXPECT_DOUBLE_EQ(fr3.intrinsics.cx(), 320.1);
	EXPECT_DOUBLE_EQ(fr3.intrinsics.dist[0], 0.0);
	EXPECT_DOUBLE_EQ(fr3.depthScale, 5000.0);
	expectInputError([] { tumCameraByName("fr4"); }, {"unknown camera name 'fr4'"});
}

TEST(Camera, NameFromFolderPath)
{
	EXPECT_EQ(tumCameraNameFromPath("/data/rgbd_dataset_freiburg3_walking_xyz"), "fr3");
	EXPECT_EQ(tumCameraNameFromPath("/data/fr2/desk"), "fr2");
	EXPECT_EQ(tumCameraNameFromPath("/data/FR1_xyz/"), "fr1");
	EXPECT_EQ(tumCameraNameFromPath("/data/my_sequence"), "");
	EXPECT_EQ(tumCameraNameFromPath("/data/fr12_other"), "");
}

TEST(Camera, CameraFileOfTheSharedFolder)
{
	// calibration.txt of the real fr1/desk frames (TUM RGB-D, CC BY 4.0).
	const auto c = readCameraFile(sharedFile("data/tum_fr1_desk_9frames/calibration.txt"));
	EXPECT_DOUBLE_EQ(c.intrinsics.fx(), 517.3);
	EXPECT_EQ(c.intrinsics.ncols, 640u);
	EXPECT_DOUBLE_EQ(c.depthScale, 5000.0);
	EXPECT_DOUBLE_EQ(c.intrinsics.dist[2], -0.0054);
}

TEST(Camera, BadCameraFilesAndSpecs)
{
	TempDir d("cam");
	writeText(d / "bad1.txt", "# nothing\n");
	expectInputError([&] { readCameraFile(d / "bad1.txt"); }, {"bad1.txt", "no numbers"});
	writeText(d / "bad2.txt", "500 500 320\n");
	expectInputError([&] { readCameraFile(d / "bad2.txt"); }, {"bad2.txt", "first line"});
	writeText(d / "bad3.txt", "500 500 320 240 640 480 -1\n");
	expectInputError([&] { readCameraFile(d / "bad3.txt"); }, {"depth_scale must be positive"});
	writeText(d / "bad4.txt", "500 x 320 240\n");
	expectInputError([&] { readCameraFile(d / "bad4.txt"); }, {"bad4.txt", "line 1", "'x'"});
	writeText(d / "ok.txt", "500 501 320 240 320 240 1000\n0.1 0.2 0.3 0.4 0.5\n");
	const auto c = resolveTumCamera(d / "ok.txt", d.path());
	EXPECT_EQ(c.intrinsics.ncols, 320u);
	EXPECT_DOUBLE_EQ(c.depthScale, 1000.0);
	EXPECT_DOUBLE_EQ(c.intrinsics.dist[4], 0.5);
	expectInputError([&] { resolveTumCamera("kinect9", d.path()); }, {"kinect9", "neither a known camera name"});
	// A folder with no calibration.txt and no freiburg name cannot be guessed.
	TempDir plain("plain_sequence");
	expectInputError([&] { resolveTumCamera("", plain.path()); }, {"cannot tell the camera"});
}

TEST(Camera, TheReadoutIsKnownForTheCamerasThatHaveOneAndNotAssumedForOthers)
{
	// Issue 42 item 4: a 28 ms readout was assumed for every camera. Now it is known for the TUM
	// presets and calibration files in freiburg or Bonn folders (Kinect v1, Xtion), given by a camera
	// file's line of one number, and unknown (-1) otherwise. Bonn RGB-D Dynamic Dataset's calibration
	// (research data, test use only: ../shared/data/bonn_crowd_dev/SOURCE.md); TUM RGB-D (CC BY 4.0).
	EXPECT_DOUBLE_EQ(tumCameraByName("fr2").readout, 0.028);
	EXPECT_DOUBLE_EQ(readCameraFile(sharedFile("data/bonn_crowd_dev/calibration.txt")).readout, -1.0);
	EXPECT_DOUBLE_EQ(resolveTumCamera("", sharedFile("data/bonn_crowd_dev")).readout, 0.028);
	EXPECT_DOUBLE_EQ(resolveTumCamera("", sharedFile("data/tum_fr1_desk_9frames")).readout, 0.028);
	TempDir d("readout_cam");
	writeText(d / "calibration.txt", "535.4 539.2 320.1 247.6\n");
	EXPECT_DOUBLE_EQ(resolveTumCamera("", d.path()).readout, -1.0) << "a camera nobody named";
	writeText(d / "rs.txt", "535.4 539.2 320.1 247.6 640 480 5000\n0.1 0.2 0.3 0.4 0.5\n0.0165\n");
	const auto c = readCameraFile(d / "rs.txt");
	EXPECT_DOUBLE_EQ(c.readout, 0.0165);
	EXPECT_DOUBLE_EQ(c.intrinsics.dist[4], 0.5);
	writeText(d / "gs.txt", "535.4 539.2 320.1 247.6\n0\n");
	EXPECT_DOUBLE_EQ(readCameraFile(d / "gs.txt").readout, 0.0) << "a global shutter, without distortion";
	writeText(d / "slow.txt", "535.4 539.2 320.1 247.6\n0.5\n");
	expectInputError([&] { readCameraFile(d / "slow.txt"); }, {"slow.txt", "readout", "0 to 0.1"});
	writeText(d / "three.txt", "535.4 539.2 320.1 247.6\n0.1 0.2 0.3 0.4 0.5\n1 2\n");
	expectInputError([&] { readCameraFile(d / "three.txt"); }, {"three.txt", "line 3", "has 2"});
}

TEST(Camera, ACameraFileMayNameItsSensorAndEveryReadoutSaysWhereItCameFrom)
{
	// Issue 70 item 2: the readout line may name the sensor ("readout kinect1", "xtion", "global")
	// instead of a number; every known readout says where it came from.
	TempDir d("named_readout");
	writeText(d / "k.txt", "517.3 516.5 318.6 255.3\n0.2624 -0.9531 -0.0054 0.0026 1.1633\nreadout kinect1\n");
	const auto k = readCameraFile(d / "k.txt");
	EXPECT_DOUBLE_EQ(k.readout, 0.028);
	EXPECT_DOUBLE_EQ(k.intrinsics.dist[0], 0.2624);
	EXPECT_NE(k.readoutSource.find("k.txt"), std::string::npos) << k.readoutSource;
	writeText(d / "x.txt", "535.4 539.2 320.1 247.6\nXtion\n");
	EXPECT_DOUBLE_EQ(readCameraFile(d / "x.txt").readout, 0.028);
	writeText(d / "g.txt", "535.4 539.2 320.1 247.6\nreadout global\n");
	EXPECT_DOUBLE_EQ(readCameraFile(d / "g.txt").readout, 0.0);
	writeText(d / "s.txt", "535.4 539.2 320.1 247.6\nreadout 0.0165\n");
	EXPECT_DOUBLE_EQ(readCameraFile(d / "s.txt").readout, 0.0165);
	writeText(d / "bad.txt", "535.4 539.2 320.1 247.6\nreadout kinect9\n");
	expectInputError([&] { readCameraFile(d / "bad.txt"); }, {"bad.txt", "line 2", "kinect9", "xtion"});
	writeText(d / "nothing.txt", "535.4 539.2 320.1 247.6\n");
	EXPECT_TRUE(readCameraFile(d / "nothing.txt").readoutSource.empty());
	EXPECT_NE(resolveTumCamera("", sharedFile("data/bonn_crowd_dev")).readoutSource.find("Bonn"), std::string::npos);
	EXPECT_NE(resolveTumCamera("fr1", d.path()).readoutSource.find("fr1"), std::string::npos);
}

TEST(Camera, ARecordingsCameraFileReadsBack)
{
	// What tum2rawlog, yesslam-oni and --record write beside a recording (NAME_camera.txt) reads
	// back as the camera it was written from, readout included; without a readout, none.
	TRgbdCamera c = tumCameraByName("fr1");
	EXPECT_EQ(recordingCameraPath("/data/run/desk.oni"), "/data/run/desk_camera.txt");
	TempDir d("recording_camera_file");
	writeText(d / "a_camera.txt", formatCameraFile(c, "the camera of a.rawlog\n(two lines)"));
	const TRgbdCamera back = readCameraFile(d / "a_camera.txt");
	EXPECT_NEAR(back.intrinsics.fx(), c.intrinsics.fx(), 1e-9);
	EXPECT_NEAR(back.intrinsics.cy(), c.intrinsics.cy(), 1e-9);
	EXPECT_EQ(back.intrinsics.ncols, c.intrinsics.ncols);
	for (int i = 0; i < 5; i++) EXPECT_NEAR(back.intrinsics.dist[i], c.intrinsics.dist[i], 1e-9) << i;
	EXPECT_DOUBLE_EQ(back.readout, 0.028);
	c.readout = -1;
	writeText(d / "b_camera.txt", formatCameraFile(c, "no readout"));
	EXPECT_DOUBLE_EQ(readCameraFile(d / "b_camera.txt").readout, -1.0);
}

TEST(Camera, AnOpenNI2DeviceSaysItsReadoutByItsNameOrUsbIds)
{
	// Issue 70 item 3: PrimeSense designs (Kinect v1, Xtion, Carmine) read their rows over 28 ms;
	// a device of another make has no readout we know of (the run then warns).
	const auto dev = [](const std::string& vendor, const std::string& name, int vid)
	{
		TOpenNI2Device d;
		d.vendor = vendor;
		d.name = name;
		d.usbVendorId = vid;
		return d;
	};
	EXPECT_EQ(deviceReadout(dev("PrimeSense", "PS1080", 0x1d27)), std::optional<double>(0.028));
	EXPECT_EQ(deviceReadout(dev("Microsoft", "Kinect", 0x045e)), std::optional<double>(0.028));
	TOpenNI2Device unnamed = dev("", "", 0x045e);
	unnamed.usbProductId = 0x02ae;
	EXPECT_EQ(deviceReadout(unnamed), std::optional<double>(0.028)) << "the Kinect v1 camera's USB ids";
	EXPECT_EQ(deviceReadout(dev("ASUS", "Xtion PRO LIVE", 0)), std::optional<double>(0.028)) << "by its name alone";
	EXPECT_EQ(deviceReadout(dev("", "", 0x1d27)), std::optional<double>(0.028)) << "by its USB vendor alone";
	EXPECT_FALSE(deviceReadout(dev("Orbbec", "Astra", 0x2bc5)).has_value());
	EXPECT_FALSE(deviceReadout(dev("Microsoft", "Kinect V2", 0x045e)).has_value()) << "time of flight, another design";
}

TEST(Camera, ASimulatedSequenceStatesItsRollingShutterAndARecordingDoesNot)
{
	// [Tracking] rollingShutter = -1 (auto): a yesslam-sim sequence's readout from its meta.json
	// (in the folder, or beside its rawlog), 0 for one made before the simulator had a rolling
	// shutter; nothing for any other input (yesslam then assumes a Kinect-class camera).
	TempDir d("stated_readout");
	const std::filesystem::path dir = d.path();
	const auto write = [](const std::filesystem::path& p, const std::string& text) { std::ofstream(p) << text; };
	EXPECT_FALSE(statedReadout(d.path()).has_value()) << "no meta.json";
	write(dir / "meta.json", "{\n  \"tool\": \"yesslam-sim\",\n  \"readout_ms\": 28.000000,\n  \"frames\": 3\n}\n");
	ASSERT_TRUE(statedReadout(d.path()).has_value());
	EXPECT_NEAR(*statedReadout(d.path()), 0.028, 1e-12);
	EXPECT_NEAR(*statedReadout((dir / "sequence.rawlog").string()), 0.028, 1e-12) << "beside a rawlog";
	write(dir / "meta.json", "{\n  \"tool\": \"yesslam-sim\",\n  \"depth_offset_ms\": 0.000000\n}\n");
	EXPECT_EQ(statedReadout(d.path()), std::optional<double>(0.0)) << "an older simulator: global shutter";
	write(dir / "meta.json", "{\n  \"tool\": \"some-recorder\",\n  \"readout_ms\": 28\n}\n");
	EXPECT_FALSE(statedReadout(d.path()).has_value()) << "only the simulator's meta.json is read";
	write(dir / "meta.json", "{\n  \"tool\": \"yesslam-sim\",\n  \"readout_ms\": 2.8e+\n}\n");
	expectInputError([&] { statedReadout(d.path()); }, {"meta.json", "readout_ms"});
}
