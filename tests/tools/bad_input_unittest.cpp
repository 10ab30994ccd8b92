// The bad-input corpus (tests/bad_inputs/): one test per case, each checking that the
// tool exits non-zero (or warns, for unknown config keys) with one line naming the file and the
// problem, and never crashes.
#include <gtest/gtest.h>

#include <filesystem>

#include "TestUtils.h"

using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
const std::string kBad = std::string(YESSLAM_SOURCE_DIR) + "/tests/bad_inputs/";

struct BadCase
{
	std::string name;  //!< test name
	std::string tool;
	std::vector<std::string> args;    //!< "@OUT" is replaced by a scratch folder
	std::vector<std::string> expect;  //!< fragments of the stderr line
	bool warnOnly = false;            //!< exit 0 with a warning line
};

std::vector<BadCase> cases()
{
	const std::string gt = sharedFile("data/tum_eval_trajectories/evo_freiburg1_xyz-groundtruth.txt");
	const std::string desk = sharedFile("data/tum_fr1_desk_9frames");
	auto eval = [&](const std::string& n, const std::string& f, std::vector<std::string> e) {
		return BadCase{n, "yesslam-eval", {"--gt", gt, "--est", kBad + f}, e};
	};
	auto tum = [&](const std::string& n, const std::string& f, std::vector<std::string> e) {
		return BadCase{n, "tum2rawlog", {"--input", kBad + f, "--output", "@OUT/x.rawlog", "--quiet"}, e};
	};
	auto rawlog = [&](const std::string& n, const std::string& f, std::vector<std::string> e) {
		return BadCase{
			n, "yesslam-cloud", {"--input", kBad + f, "--poses", gt, "--out", "@OUT/x.3Dscene", "--quiet"}, e};
	};
	return {
		eval("MissingTrajectory", "no_such_file.txt", {"no_such_file.txt", "not found"}),
		eval("EmptyTrajectory", "trajectory_empty.txt", {"trajectory_empty.txt", "no poses"}),
		eval("TrajectorySixNumbers", "trajectory_six_numbers.txt",
			 {"trajectory_six_numbers.txt", "line 2", "expected 8"}),
		eval("TrajectoryNaN", "trajectory_nan.txt", {"trajectory_nan.txt", "line 1", "'nan' is not a finite number"}),
		eval("TrajectoryInf", "trajectory_inf.txt", {"trajectory_inf.txt", "'inf' is not a finite number"}),
		eval("TrajectoryZeroQuaternion", "trajectory_zero_quaternion.txt",
			 {"trajectory_zero_quaternion.txt", "zero norm"}),
		tum("MissingFolder", "no_such_folder", {"no_such_folder", "folder not found"}),
		tum("TruncatedPng", "tum_truncated_png", {"depth/0.png", "cannot decode depth image"}),
		tum("Depth8Bit", "tum_depth_8bit", {"depth/0.png", "8-bit"}),
		tum("DepthFloatMetres", "tum_depth_float_metres", {"depth/0.tiff", "floating-point"}),
		tum("WrongImageSize", "tum_wrong_size", {"depth/0.png", "4x3", "8x6"}),
		tum("RgbTxtPointsToMissingImage", "tum_missing_image", {"rgb/0.png", "not found"}),
		tum("NonMonotonicTimestamps", "tum_backwards_stamps", {"rgb.txt", "line 2", "earlier"}),
		tum("NoMatchingDepth", "tum_no_matching_depth", {"rgb.txt", "no image has a depth.txt entry"}),
		tum("EmptyLists", "tum_empty_lists", {"rgb.txt", "lists no images"}),
		tum("NoCameraKnown", "tum_no_calibration", {"tum_no_calibration", "cannot tell the camera"}),
		BadCase{"CameraFileThreeNumbers",
				"tum2rawlog",
				{"--input", kBad + "tum_no_calibration", "--output", "@OUT/x.rawlog", "--camera",
				 kBad + "camera_three_numbers.txt"},
				{"camera_three_numbers.txt", "first line"}},
		BadCase{"UnknownCameraName",
				"tum2rawlog",
				{"--input", kBad + "tum_no_calibration", "--output", "@OUT/x.rawlog", "--camera", "kinect2"},
				{"kinect2", "neither a known camera name"}},
		BadCase{"ConfigUnknownKeyWarns",
				"tum2rawlog",
				{"--input", desk, "--output", "@OUT/x.rawlog", "--max-frames", "1", "--quiet", "--config",
				 kBad + "config_unknown_key.ini"},
				{"config_unknown_key.ini", "[Input] unknown key 'maxdiff_typo'"},
				true},
		BadCase{"ConfigWrongTypeIni",
				"tum2rawlog",
				{"--input", desk, "--output", "@OUT/x.rawlog", "--config", kBad + "config_wrong_type.ini"},
				{"config_wrong_type.ini", "maxDiff", "expected a number"}},
		BadCase{"ConfigWrongTypeYaml",
				"tum2rawlog",
				{"--input", desk, "--output", "@OUT/x.rawlog", "--config", kBad + "config_wrong_type.yaml"},
				{"config_wrong_type.yaml", "maxDiff", "expected a number"}},
		BadCase{"ModelNotAModel",
				"yesslam-detect",
				{"--model", kBad + "model_not_a_model.onnx", "--names",
				 sharedFile("models/yolox_nano_onnx/coco_classes.txt"), "--input",
				 sharedFile("data/detector_test_images/person.jpg"), "--out", "@OUT/det", "--quiet"},
				{"model_not_a_model.onnx", "cannot load model"}},
		BadCase{"NamesWrongCount",
				"yesslam-detect",
				{"--model", sharedFile("models/yolo_fastest_darknet/yolo-fastest-1.1.cfg"), "--weights",
				 sharedFile("models/yolo_fastest_darknet/yolo-fastest-1.1.weights"), "--names",
				 sharedFile("models/yolo_fastest_darknet/body.names"), "--input",
				 sharedFile("data/detector_test_images/person.jpg"), "--out", "@OUT/det", "--quiet"},
				{"body.names", "1 class names but the model outputs 80"}},
		BadCase{"SimUnknownPreset",
				"yesslam-sim",
				{"--preset", "walking_fast", "--out", "@OUT/sim", "--quiet"},
				{"unknown preset 'walking_fast'"}},
		BadCase{"SimUnwritableFolder",
				"yesslam-sim",
				{"--preset", "walking_xyz", "--out", kBad + "trajectory_empty.txt/sub", "--frames", "2", "--quiet"},
				{"trajectory_empty.txt/sub", "cannot create output folder"}},
		BadCase{"SimTrajectoryUnparsable",
				"yesslam-sim",
				{"--preset", "walking_xyz", "--out", "@OUT/sim", "--trajectory", kBad + "trajectory_six_numbers.txt",
				 "--quiet"},
				{"trajectory_six_numbers.txt", "line 2", "expected 8"}},
		rawlog("EmptyRawlog", "empty.rawlog", {"empty.rawlog", "empty"}),
		rawlog("TextRawlog", "text.rawlog", {"text.rawlog", "corrupt or truncated rawlog at entry 1"}),
		rawlog("TruncatedRawlog", "truncated.rawlog", {"truncated.rawlog", "corrupt or truncated rawlog at entry 2"}),
		// Found by fuzz_rawlog: a range image of absurd size made MRPT's deserialiser crash.
		rawlog("RawlogHugeImage", "rawlog_huge_image.rawlog",
			   {"rawlog_huge_image.rawlog", "corrupt or truncated rawlog", "bad_alloc"}),
	};
}

class BadInput : public ::testing::TestWithParam<BadCase>
{
};
}  // namespace

TEST_P(BadInput, ClearOneLineMessageAndExitCode)
{
	const BadCase& c = GetParam();
	TempDir out("bad");
	std::vector<std::string> args;
	for (auto a : c.args)
	{
		if (a.rfind("@OUT", 0) == 0) a = out.path() + a.substr(4);
		args.push_back(a);
	}
	const RunResult r = runTool(c.tool, args);
	EXPECT_LT(r.exitCode, 128) << "crashed (signal): " << r.err;
	if (c.warnOnly)
		EXPECT_EQ(r.exitCode, 0) << r.err;
	else
		EXPECT_EQ(r.exitCode, 1) << r.err;
	const std::string firstLine = r.err.substr(0, r.err.find('\n'));
	for (const auto& f : c.expect)
		EXPECT_NE(firstLine.find(f), std::string::npos) << "stderr: " << r.err << "\nmissing: " << f;
	if (!c.warnOnly)
	{
		EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "expected exactly one line: " << r.err;
		// Nothing half-written is left behind.
		EXPECT_TRUE(fs::is_empty(out.path()));
	}
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadInput, ::testing::ValuesIn(cases()),
						 [](const ::testing::TestParamInfo<BadCase>& i) { return i.param.name; });
