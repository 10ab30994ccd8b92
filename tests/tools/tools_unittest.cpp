// The command-line contract of the tools: outputs, exit codes, and one-line errors for bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include <octomap/OcTree.h>

#include "TestUtils.h"
#include "mrpt_yesslam/io/RgbdCamera.h"
#include "mrpt_yesslam/dense/DenseMapExport.h"
#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/io/CRawlogSource.h"
#include "mrpt_yesslam/io/Trajectory.h"

using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
// A failed run: non-zero exit, exactly one stderr line, naming what is wrong.
void expectCleanFailure(const RunResult& r, const std::vector<std::string>& fragments)
{
	EXPECT_NE(r.exitCode, 0);
	EXPECT_LT(r.exitCode, 128) << "killed by a signal: " << r.err;
	EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
	for (const auto& f : fragments)
		EXPECT_NE(r.err.find(f), std::string::npos) << "stderr: " << r.err << "\nmissing: " << f;
}

std::string value(const std::string& out, const std::string& key)
{
	const auto p = out.find("\n" + key + ": ");
	const auto q = p == std::string::npos ? (out.rfind(key + ": ", 0) == 0 ? 0 : std::string::npos) : p + 1;
	if (q == std::string::npos) return {};
	auto s = q + key.size() + 2;
	while (s < out.size() && out[s] == ' ') s++;
	return out.substr(s, out.find('\n', s) - s);
}

const std::string kTraj = "data/tum_eval_trajectories/";
}  // namespace

TEST(Tools, EvalPrintsTheContractKeys)
{
	TempDir d("eval");
	const auto r = runTool("yesslam-eval", {"--gt", sharedFile(kTraj + "evo_fr2_desk_groundtruth.txt"), "--est",
											sharedFile(kTraj + "evo_fr2_desk_ORB.txt"), "--json", d / "r.json",
											"--plot", d / "r.png", "--errors", d / "r.csv"});
	ASSERT_EQ(r.exitCode, 0) << r.err;
	for (const char* k : {"ate_pairs", "ate_rmse", "ate_mean", "ate_median", "ate_std", "ate_min", "ate_max",
						  "rpe_pairs", "rpe_trans_rmse", "rpe_rot_rmse_deg"})
		EXPECT_FALSE(value(r.out, k).empty()) << k << " missing in\n" << r.out;
	EXPECT_EQ(value(r.out, "ate_pairs"), "2223");
	EXPECT_NEAR(std::stod(value(r.out, "ate_rmse")), 0.008144, 1e-6);
	EXPECT_EQ(value(r.out, "rpe_pairs"), "1998");
	EXPECT_TRUE(fs::file_size(d / "r.json") > 100);
	EXPECT_TRUE(fs::file_size(d / "r.png") > 1000);
	// The errors table: a header and one row per matched pair.
	std::ifstream errs(d / "r.csv");
	std::string line;
	std::getline(errs, line);
	EXPECT_EQ(line, "stamp,error,dx,dy,dz");
	int rows = 0;
	while (std::getline(errs, line)) rows++;
	EXPECT_EQ(rows, 2223);

	// RPE in frames: pairs i, i+30; those whose partner would be the last pose are dropped.
	const auto f =
		runTool("yesslam-eval", {"--gt", sharedFile(kTraj + "evo_fr2_desk_groundtruth.txt"), "--est",
								 sharedFile(kTraj + "evo_fr2_desk_ORB.txt"), "--rpe-delta", "30", "--rpe-unit", "f"});
	ASSERT_EQ(f.exitCode, 0) << f.err;
	EXPECT_EQ(value(f.out, "rpe_unit"), "f");
	// (Some pairs fall in ground-truth gaps longer than twice its median period and are dropped.)
	EXPECT_LE(std::stoi(value(f.out, "rpe_pairs")), 2893 - 31);
	EXPECT_GT(std::stoi(value(f.out, "rpe_pairs")), 1900);

	const auto s = runTool("yesslam-eval", {"--gt", sharedFile(kTraj + "evo_fr2_desk_groundtruth.txt"), "--est",
											sharedFile(kTraj + "evo_fr2_desk_ORB_kf_mono.txt"), "--sim3"});
	ASSERT_EQ(s.exitCode, 0) << s.err;
	EXPECT_EQ(value(s.out, "alignment"), "sim3");
	EXPECT_NEAR(std::stod(value(s.out, "scale")), 2.2283, 1e-4);
}

TEST(Tools, EvalBadInput)
{
	TempDir d("evalbad");
	const std::string gt = sharedFile(kTraj + "evo_freiburg1_xyz-groundtruth.txt");
	writeText(d / "six.txt", "# x\n1305031102.16 1 2 3 4 5\n");
	expectCleanFailure(runTool("yesslam-eval", {"--gt", gt, "--est", d / "six.txt"}),
					   {"six.txt", "line 2", "expected 8"});
	writeText(d / "nan.txt", "1305031102.16 1 2 nan 0 0 0 1\n");
	expectCleanFailure(runTool("yesslam-eval", {"--gt", gt, "--est", d / "nan.txt"}),
					   {"nan.txt", "not a finite number"});
	expectCleanFailure(runTool("yesslam-eval", {"--gt", gt, "--est", sharedFile(kTraj + "evo_fr2_desk_ORB.txt")}),
					   {"evo_fr2_desk_ORB.txt", "only 0 of 2893 poses"});
	expectCleanFailure(runTool("yesslam-eval", {"--gt", gt, "--est", d / "missing.txt"}), {"missing.txt", "not found"});
	writeText(d / "empty.txt", "# nothing\n");
	expectCleanFailure(runTool("yesslam-eval", {"--gt", gt, "--est", d / "empty.txt"}), {"empty.txt", "no poses"});
	expectCleanFailure(runTool("yesslam-eval", {"--gt", gt}), {"missing required option --est"});
	expectCleanFailure(runTool("yesslam-eval", {"--gt", gt, "--est", gt, "--loops", gt}), {"--loops and --est"});
	expectCleanFailure(runTool("yesslam-eval", {"--gt", gt, "--loops", gt}), {"not a loop_candidates.csv"});
	expectCleanFailure(runTool("yesslam-eval", {"--gt", gt, "--est", gt, "--max-diff", "abc"}),
					   {"--max-diff expects a number"});
	expectCleanFailure(runTool("yesslam-eval", {"--gt", gt, "--est", gt, "--rpe-unit", "m"}), {"--rpe-unit"});
	expectCleanFailure(runTool("yesslam-eval", {"--bogus"}), {"unknown option --bogus"});
	const auto h = runTool("yesslam-eval", {"--help"});
	EXPECT_EQ(h.exitCode, 0);
	for (const char* o :
		 {"--gt", "--est", "--max-diff", "--offset", "--sim3", "--rpe-delta", "--rpe-unit", "--json", "--plot"})
		EXPECT_NE(h.out.find(o), std::string::npos) << o;
}

TEST(Tools, Tum2RawlogConvertsAndSummarises)
{
	TempDir d("t2r");
	const auto frames = makeSyntheticFrames(5);
	writeTumFolder(d / "seq", frames);
	const auto r = runTool("tum2rawlog", {"--input", d / "seq", "--output", d / "seq.rawlog", "--quiet"});
	ASSERT_EQ(r.exitCode, 0) << r.err;
	EXPECT_EQ(value(r.out, "frames"), "5");
	EXPECT_NE(value(r.out, "skipped").rfind("0", 0), std::string::npos);
	EXPECT_NE(r.out.find("seq_groundtruth.txt"), std::string::npos);
	mrpt_yesslam::CRawlogSource src(d / "seq.rawlog");
	int n = 0;
	while (auto obs = src.next())
	{
		EXPECT_EQ(obs->rangeImage(5, 9), frames[n].depth.at<uint16_t>(5, 9));
		n++;
	}
	EXPECT_EQ(n, 5);

	const auto e = runTool(
		"tum2rawlog", {"--input", d / "seq", "--output", d / "ext.rawlog", "--external-images", "--max-frames", "2"});
	ASSERT_EQ(e.exitCode, 0) << e.err;
	EXPECT_EQ(value(e.out, "frames"), "2");
	EXPECT_TRUE(fs::is_directory(d / "ext_Images"));
	// Progress goes to stderr, the summary to stdout.
	EXPECT_NE(e.err.find("tum2rawlog"), std::string::npos);
}

TEST(Tools, RawlogsOpenInMrptsRawlogEdit)
{
	// The rawlogs of tum2rawlog (inline and external images) and of yesslam-sim must be usable by
	// MRPT's own tools, not only by our reader: rawlog-edit (Debian package mrpt-apps, installed
	// by scripts/install_deps.sh) counts every frame and loads every image and depth to build
	// point clouds from them.
	// rawlog-edit prints "Key      : value" lines.
	auto field = [](const RunResult& r, const std::string& key) -> std::string
	{
		const std::string all = r.out + r.err;
		const auto k = all.find(key);
		if (k == std::string::npos) return {};
		auto c = all.find(':', k + key.size());
		if (c == std::string::npos) return {};
		c++;
		while (c < all.size() && all[c] == ' ') c++;
		return all.substr(c, all.find('\n', c) - c);
	};
	TempDir d("rawlog_edit");
	writeTumFolder(d / "seq", makeSyntheticFrames(4));
	ASSERT_EQ(runTool("tum2rawlog", {"--input", d / "seq", "--output", d / "inline.rawlog", "--quiet"}).exitCode, 0);
	ASSERT_EQ(
		runTool("tum2rawlog", {"--input", d / "seq", "--output", d / "ext.rawlog", "--external-images", "--quiet"})
			.exitCode,
		0);
	const auto sim =
		runTool("yesslam-sim", {"--preset", "walking_xyz", "--frames", "3", "--out", d / "sim", "--quiet"});
	ASSERT_EQ(sim.exitCode, 0) << sim.err;
	for (const auto& [file, frames] : std::vector<std::pair<std::string, std::string>>{
			 {d / "inline.rawlog", "4"}, {d / "ext.rawlog", "4"}, {d / "sim/sequence.rawlog", "3"}})
	{
		SCOPED_TRACE(file);
		const auto info = runCommand("rawlog-edit", {"-i", file, "--info"});
		ASSERT_NE(info.exitCode, 127)
			<< "rawlog-edit not found: install Debian's mrpt-apps (scripts/install_deps.sh does)";
		ASSERT_EQ(info.exitCode, 0) << info.out << info.err;
		EXPECT_EQ(field(info, "Overall number of objects"), frames) << info.out;
		const auto pc = runCommand("rawlog-edit", {"-i", file, "--generate-3d-pointclouds", "-o", file + ".pc.rawlog"});
		ASSERT_EQ(pc.exitCode, 0) << pc.out << pc.err;
		EXPECT_EQ(field(pc, "Entries modified"), frames) << pc.out;
		EXPECT_GT(fs::file_size(file + ".pc.rawlog"), fs::file_size(file)) << "no point clouds were added";
	}
	// Issue 18 item 7: MRPT resolves external images against the working directory, so
	// rawlog-edit must run from the rawlog's folder to reach them (what docs/tools.md says): from there
	// --de-externalize embeds the images; from elsewhere it silently writes a rawlog without them.
	const auto here =
		runCommand("sh", {"-c", "cd '" + d.path() + "' && rawlog-edit -i ext.rawlog --de-externalize -o here.rawlog"});
	ASSERT_EQ(here.exitCode, 0) << here.out << here.err;
	EXPECT_GT(fs::file_size(d / "here.rawlog"), fs::file_size(d / "ext.rawlog") + 4 * 64 * 48)
		<< "the images were not embedded";
	const auto away = runCommand("sh", {"-c", "cd / && rawlog-edit -i '" + (d / "ext.rawlog") +
												  "' --de-externalize -o '" + (d / "away.rawlog") + "'"});
	ASSERT_EQ(away.exitCode, 0) << away.out << away.err;
	EXPECT_LT(fs::file_size(d / "away.rawlog"), fs::file_size(d / "here.rawlog"));
}

TEST(Tools, Tum2RawlogBadInput)
{
	TempDir d("t2rbad");
	expectCleanFailure(runTool("tum2rawlog", {"--input", d / "nope", "--output", d / "x.rawlog"}),
					   {"nope", "folder not found"});
	writeTumFolder(d / "seq", makeSyntheticFrames(2));
	expectCleanFailure(runTool("tum2rawlog", {"--input", d / "seq", "--output", d / "x.rawlog", "--camera", "fr9"}),
					   {"fr9", "neither a known camera name"});
	// A missing output folder is made (issue 43); one that cannot be made is named.
	const auto made = runTool("tum2rawlog", {"--input", d / "seq", "--output", d / "new/dir/x.rawlog"});
	EXPECT_EQ(made.exitCode, 0) << made.err;
	EXPECT_TRUE(fs::is_regular_file(d / "new/dir/x.rawlog"));
	writeText(d / "afile", "x");
	expectCleanFailure(runTool("tum2rawlog", {"--input", d / "seq", "--output", d / "afile/x.rawlog"}),
					   {"x.rawlog", "cannot create the output folder"});
	fs::remove(d / "seq/depth/1000.037333.png");
	expectCleanFailure(runTool("tum2rawlog", {"--input", d / "seq", "--output", d / "y.rawlog"}),
					   {"1000.037333.png", "not found"});
	EXPECT_FALSE(fs::exists(d / "y.rawlog")) << "a failed conversion must not leave a partial rawlog";
	int leftovers = 0;
	for (const auto& e : fs::directory_iterator(d.path()))
		leftovers += e.path().string().find(".tmp.") != std::string::npos;
	EXPECT_EQ(leftovers, 0);
}

TEST(Tools, RenderCliAndErrors)
{
	TempDir d("rendercli");
	expectCleanFailure(runTool("yesslam-render", {"--scene", d / "none.3Dscene", "--out", d / "x.png"}),
					   {"none.3Dscene", "not found"});
	expectCleanFailure(
		runTool("yesslam-render", {"--scene", d / "none.3Dscene", "--out", d / "x.png", "--look-at", "1,2"}),
		{"--look-at expects three numbers"});
	const auto h = runTool("yesslam-render", {"--help"});
	EXPECT_EQ(h.exitCode, 0);
	for (const char* o : {"--width", "--height", "--azimuth", "--elevation", "--distance", "--look-at"})
		EXPECT_NE(h.out.find(o), std::string::npos) << o;
}

TEST(Tools, CloudOfRealFramesRendersAndRejectsBadPoses)
{
	// 9 real TUM fr1/desk frames with their motion-capture ground truth (TUM RGB-D, CC BY 4.0).
	TempDir d("cloud");
	const std::string folder = sharedFile("data/tum_fr1_desk_9frames");
	const auto c = runTool("yesslam-cloud", {"--input", folder, "--poses", folder + "/groundtruth.txt", "--out",
											 d / "desk.3Dscene", "--quiet"});
	ASSERT_EQ(c.exitCode, 0) << c.err;
	EXPECT_EQ(value(c.out, "frames used"), "9");
	EXPECT_GT(std::stol(value(c.out, "points")), 100000);
	// Into a folder it makes (issue 63 item 6: it failed, "cannot open for writing").
	const auto r = runTool("yesslam-render", {"--scene", d / "desk.3Dscene", "--out", d / "pictures/desk.png",
											  "--width", "400", "--height", "300"});
	ASSERT_EQ(r.exitCode, 0) << r.err;
	EXPECT_TRUE(fs::is_regular_file(d / "pictures/desk.png"));
	EXPECT_NE(r.out.find("of pixels show the scene"), std::string::npos);
	EXPECT_EQ(r.out.find("(0.0% of pixels"), std::string::npos) << r.out;
	// Issue 18 item 6: a .jpg name gets a JPEG, an unknown extension an error, never a mislabelled PNG.
	ASSERT_EQ(runTool("yesslam-render",
					  {"--scene", d / "desk.3Dscene", "--out", d / "desk.jpg", "--width", "200", "--height", "150"})
				  .exitCode,
			  0);
	EXPECT_EQ(readText(d / "desk.jpg").substr(0, 3), std::string("\xFF\xD8\xFF"));
	expectCleanFailure(runTool("yesslam-render", {"--scene", d / "desk.3Dscene", "--out", d / "desk.gif", "--width",
												  "200", "--height", "150"}),
					   {"desk.gif", "unknown image type '.gif' (use .png or .jpg)"});
	EXPECT_FALSE(fs::exists(d / "desk.gif"));
	// A camera that sees only a corner of the cloud from far away: the blank-picture warning.
	const auto corner =
		runTool("yesslam-render", {"--scene", d / "desk.3Dscene", "--out", d / "corner.png", "--width", "200",
								   "--height", "150", "--look-at", "30,30,30", "--distance", "5"});
	ASSERT_EQ(corner.exitCode, 0) << corner.err;
	EXPECT_NE(corner.err.find("warning: the picture is"), std::string::npos) << corner.out << corner.err;
	EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;

	// Poses from another sequence: no frame has a pose, said clearly.
	expectCleanFailure(
		runTool("yesslam-cloud", {"--input", folder, "--poses", sharedFile(kTraj + "evo_fr2_desk_groundtruth.txt"),
								  "--out", d / "x.3Dscene", "--quiet"}),
		{"tum_fr1_desk_9frames", "no frame has a pose"});
	EXPECT_FALSE(fs::exists(d / "x.3Dscene"));
}

TEST(Tools, DetectOnImageAndTumFolder)
{
	// Yolo-Fastest (darknet YOLO licence) on darknet's person.jpg (public domain) and on the 9 real
	// fr1/desk frames (TUM RGB-D, CC BY 4.0), which have depth and so get masks.
	TempDir d("detect");
	const std::string m = "models/yolo_fastest_darknet/";
	const std::vector<std::string> model = {
		"--model", sharedFile(m + "yolo-fastest-1.1.cfg"), "--weights", sharedFile(m + "yolo-fastest-1.1.weights"),
		"--names", sharedFile(m + "coco.names"),           "--quiet"};
	auto args = model;
	for (const auto& a :
		 {std::string("--input"), sharedFile("data/detector_test_images/person.jpg"), std::string("--out"), d / "img",
		  std::string("--overlay"), std::string("--conf"), std::string("0.5")})
		args.push_back(a);
	const auto r = runTool("yesslam-detect", args);
	ASSERT_EQ(r.exitCode, 0) << r.err;
	std::ifstream f(d / "img/detections.txt");
	std::string line;
	int people = 0, lines = 0;
	while (std::getline(f, line))
	{
		if (line.empty() || line[0] == '#') continue;
		lines++;
		std::istringstream ss(line);
		double t, cls, score;
		ss >> t >> cls >> score;
		EXPECT_EQ(t, 0.0);
		EXPECT_GE(score, 0.5);
		people += cls == 0;
	}
	EXPECT_EQ(people, 1) << "one person in person.jpg";
	EXPECT_GE(lines, 2) << "and the dog and horse";
	EXPECT_TRUE(fs::exists(d / "img/overlays/0.000000.png"));
	// Without --model: the shipped Yolo-Fastest-1.1 (the same files), so the same detections
	// (issue 30 item 8: --model and --names were required).
	const auto shipped = runTool("yesslam-detect", {"--input", sharedFile("data/detector_test_images/person.jpg"),
													"--out", d / "shipped", "--conf", "0.5", "--quiet"});
	ASSERT_EQ(shipped.exitCode, 0) << shipped.err;
	EXPECT_EQ(readText(d / "shipped/detections.txt"), readText(d / "img/detections.txt"));
	const auto noNames =
		runTool("yesslam-detect", {"--model", sharedFile(m + "yolo-fastest-1.1.cfg"), "--input",
								   sharedFile("data/detector_test_images/person.jpg"), "--out", d / "x"});
	EXPECT_EQ(noNames.exitCode, 1);
	EXPECT_NE(noNames.err.find("--names"), std::string::npos) << noNames.err;

	args = model;
	for (const auto& a :
		 {std::string("--input"), sharedFile("data/tum_fr1_desk_9frames"), std::string("--out"), d / "tum"})
		args.push_back(a);
	const auto t = runTool("yesslam-detect", args);
	ASSERT_EQ(t.exitCode, 0) << t.err;
	EXPECT_EQ(value(t.out, "frames"), "9");
	EXPECT_EQ(std::distance(fs::directory_iterator(d / "tum/masks"), fs::directory_iterator()), 9);
	// No people on the desk: every mask is empty.
	for (const auto& e : fs::directory_iterator(d / "tum/masks"))
		EXPECT_EQ(cv::countNonZero(cv::imread(e.path().string(), cv::IMREAD_GRAYSCALE)), 0) << e.path();
}

TEST(Tools, ThePaperConfigurationRunsThePapersPipelineAsWritten)
{
	// share/mrpt_yesslam/config/paper.ini switches off what we add beyond the paper; the run says
	// so in config_used.ini and still tracks the generated walking sequence (measured 19.7 mm,
	// against 4.9 mm with the default configuration).
	TempDir d("paper_ini");
	const std::string cfg = std::string(YESSLAM_SOURCE_DIR) + "/share/mrpt_yesslam/config/paper.ini";
	const auto r = runTool(
		"yesslam", {"--input", walkingSequence60(), "--config", cfg, "--out", d / "run", "--sequential", "--quiet"});
	ASSERT_EQ(r.exitCode, 0) << r.err;
	EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;  // every key of paper.ini is known
	EXPECT_EQ(value(r.out, "tracked").substr(0, 10), "60 (100.0%");
	EXPECT_LT(std::stod(value(r.out, "ate_rmse")), 0.05);
	const std::string used = readText(d / "run/config_used.ini");
	for (const char* k : {"fillCompare = seed", "maxDepthRange = 0", "holdFrames = 0", "motionReference = previous",
						  "forceTrackedRatio = 0", "semanticRefRatio = 1", "etaAsWritten = true",
						  "normaliseBow = false", "seeThroughFrames = 0", "depthNoise = 0"})
		EXPECT_NE(used.find(std::string("\n") + k + "\n"), std::string::npos) << k;
	EXPECT_EQ(used.find("depthNoise = 0.0025"), std::string::npos) << "eq. 7 and eq. 24 without the depth term";
}

TEST(Tools, OutputsAreZUpLevelledByTheFloorAndOpticalKeepsTheFirstCamerasFrame)
{
	// Issue 30 item 4: yesslam-sim's ground truth is z-up with the floor at z = 0, so a levelled
	// export puts every camera at its true height with its true tilt (the heading and the
	// horizontal origin are the first camera's, so only z and the up axis are compared). Before,
	// every output was in the first camera's optical frame: z forward, the floor a wall.
	TempDir d("world_frame");
	const std::string seq = walkingSequence60();
	const auto r = runTool("yesslam", {"--input", seq, "--out", d / "run", "--sequential", "--quiet"});
	ASSERT_EQ(r.exitCode, 0) << r.err;
	const std::string head = readText(d / "run/trajectory.txt");
	EXPECT_NE(head.find("# world frame: zup (x forward, y left, z up), levelled by the floor plane: floor at z = 0"),
			  std::string::npos)
		<< head.substr(0, 400);
	EXPECT_NE(head.find("# T_world_map: "), std::string::npos);
	// Issue 42 item 4: the dense cloud's header names the frame its points are in (it said
	// "world = first keyframe" over z-up points).
	const std::string ply = readText(d / "run/dense_cloud.ply");
	const std::string plyHead = ply.substr(0, ply.find("end_header"));
	EXPECT_NE(plyHead.find("comment world frame: zup (x forward, y left, z up), levelled by the floor plane"),
			  std::string::npos)
		<< plyHead;
	EXPECT_NE(plyHead.find("comment T_world_map: "), std::string::npos) << plyHead;
	EXPECT_EQ(plyHead.find("world = first keyframe"), std::string::npos) << plyHead;
	const auto est = mrpt_yesslam::readTumTrajectory(d / "run/trajectory.txt");
	const auto gt = mrpt_yesslam::readTumTrajectory(seq + "/groundtruth.txt");
	std::map<long long, mrpt::poses::CPose3D> truth;
	for (const auto& p : gt) truth[std::llround(p.t * 1000)] = p.asPose();
	std::size_t n = 0;
	double worstZ = 0, worstTilt = 0;
	for (const auto& e : est)
	{
		const auto it = truth.find(std::llround(e.t * 1000));
		if (it == truth.end()) continue;
		// Copies: asEigen() of a temporary is a view of memory gone at the end of the statement.
		const Eigen::Matrix3d a = e.asPose().getRotationMatrix().asEigen(),
							  b = it->second.getRotationMatrix().asEigen();
		worstZ = std::max(worstZ, std::abs(e.tz - it->second.z()));
		worstTilt = std::max(worstTilt, mrpt::RAD2DEG(std::acos(std::clamp(a.row(2).dot(b.row(2)), -1.0, 1.0))));
		n++;
	}
	EXPECT_EQ(n, 60u);
	EXPECT_LT(worstZ, 0.03) << "camera height above the floor, m";
	EXPECT_LT(worstTilt, 1.5) << "degrees between the estimated and the true up axis in the camera";
	// The OctoMap navigation stacks read: the floor is a layer at z = 0, nothing occupied under it.
	octomap::OcTree bt(d / "run/map.bt");
	std::size_t occupied = 0, floor = 0, under = 0;
	for (auto it = bt.begin_leafs(), end = bt.end_leafs(); it != end; ++it)
		if (bt.isNodeOccupied(*it))
		{
			occupied++;
			floor += std::abs(it.getZ()) < 0.05;
			under += it.getZ() < -0.1;
		}
	EXPECT_GT(floor, occupied / 10) << occupied << " occupied";
	EXPECT_LT(under, occupied / 100 + 1) << occupied << " occupied";

	// optical: today's frame, the first keyframe's camera at the origin.
	const auto o = runTool("yesslam", {"--input", seq, "--out", d / "optical", "--sequential", "--quiet",
									   "--no-dense-map", "--world-frame", "optical"});
	ASSERT_EQ(o.exitCode, 0) << o.err;
	EXPECT_NE(readText(d / "optical/trajectory.txt").find("# world frame: optical"), std::string::npos);
	const auto first = mrpt_yesslam::readTumTrajectory(d / "optical/trajectory.txt").at(0);
	EXPECT_NEAR(std::abs(first.qw), 1.0, 1e-9);
	EXPECT_NEAR(std::hypot(first.tx, first.ty, first.tz), 0.0, 1e-9);
	expectCleanFailure(runTool("yesslam", {"--input", seq, "--out", d / "x", "--world-frame", "enu"}),
					   {"--world-frame", "enu"});
}

TEST(Tools, ARecordingKeepsTheCamerasReadoutAndItsReplayUsesIt)
{
	// Issue 62 item 5 / issue 70: a rawlog or an .oni holds no rolling-shutter readout (an .oni no
	// distortion either): tum2rawlog, yesslam-oni and yesslam --record write the camera beside the
	// recording (NAME_camera.txt), and a replay, through OpenNI2's file driver too, uses it. 9 real
	// TUM fr1/desk frames (TUM RGB-D, CC BY 4.0): the folder's name says fr1, so 28 ms.
	TempDir d("recording_camera");
	const std::string desk = sharedFile("data/tum_fr1_desk_9frames");
	const auto conv = runTool("tum2rawlog", {"--input", desk, "--output", d / "desk.rawlog", "--quiet"});
	ASSERT_EQ(conv.exitCode, 0) << conv.err;
	ASSERT_TRUE(fs::exists(d / "desk_camera.txt"));
	const auto cam = mrpt_yesslam::readCameraFile(d / "desk_camera.txt");
	EXPECT_DOUBLE_EQ(cam.readout, 0.028);
	EXPECT_NEAR(cam.intrinsics.dist[0], 0.2624, 1e-9);
	const auto slamArgs = [&](const std::string& input, const std::string& out)
	{
		return std::vector<std::string>{"--input", input,          "--out",   d / out,         "--detector",
										"none",    "--sequential", "--quiet", "--no-dense-map"};
	};
	// The rawlog to an .oni: its camera file carries the rawlog's readout and distortion on.
	const auto oni = runTool("yesslam-oni", {"--input", d / "desk.rawlog", "--output", d / "desk2.oni", "--quiet"});
	ASSERT_EQ(oni.exitCode, 0) << oni.err;
	EXPECT_NE(readText(d / "desk2_camera.txt").find("(yesslam-oni, from"), std::string::npos);
	const auto oniCam = mrpt_yesslam::readCameraFile(d / "desk2_camera.txt");
	EXPECT_DOUBLE_EQ(oniCam.readout, 0.028);
	EXPECT_NEAR(oniCam.intrinsics.dist[0], 0.2624, 1e-9) << "the distortion an .oni cannot hold";
	const auto fromOni = runTool("yesslam", slamArgs("openni2:" + (d / "desk2.oni"), "oni_run"));
	ASSERT_EQ(fromOni.exitCode, 0) << fromOni.err;
	EXPECT_NE(value(fromOni.out, "rolling shutter").find("28 ms readout, from the recording's camera file"),
			  std::string::npos)
		<< fromOni.out;
	// yesslam --record keeps the readout the run used.
	const auto rec = runTool("yesslam",
							 [&]
							 {
								 auto a = slamArgs(desk, "rec_run");
								 a.push_back("--record");
								 a.push_back(d / "rec.rawlog");
								 return a;
							 }());
	ASSERT_EQ(rec.exitCode, 0) << rec.err;
	ASSERT_TRUE(fs::exists(d / "rec_camera.txt"));
	EXPECT_DOUBLE_EQ(mrpt_yesslam::readCameraFile(d / "rec_camera.txt").readout, 0.028);
	const auto replay = runTool("yesslam", slamArgs(d / "rec.rawlog", "replay_run"));
	ASSERT_EQ(replay.exitCode, 0) << replay.err;
	EXPECT_NE(value(replay.out, "rolling shutter").find("28 ms readout"), std::string::npos) << replay.out;
	EXPECT_EQ(
		readText(d / "replay_run/trajectory_online.txt")
			.substr(readText(d / "replay_run/trajectory_online.txt").find("\n1")),
		readText(d / "rec_run/trajectory_online.txt").substr(readText(d / "rec_run/trajectory_online.txt").find("\n1")))
		<< "a replay of the recording gives the run's poses";
}

TEST(Tools, SlamAppOnRealFramesAndItsErrors)
{
	// yesslam on the 9 real fr1/desk frames (TUM RGB-D, CC BY 4.0): the ground truth beside the input
	// is found and evaluated; then the CLI's one-line errors.
	TempDir d("slam_app");
	const std::string desk = sharedFile("data/tum_fr1_desk_9frames");
	const auto r =
		runTool("yesslam", {"--input", desk, "--out", d / "run", "--detector", "none", "--sequential", "--quiet"});
	ASSERT_EQ(r.exitCode, 0) << r.err;
	EXPECT_EQ(value(r.out, "frames"), "9");
	EXPECT_EQ(value(r.out, "tracked").substr(0, 9), "9 (100.0%");
	EXPECT_LT(std::stod(value(r.out, "ate_rmse")), 0.01);
	EXPECT_EQ(value(r.out, "ate_pairs"), "9");
	for (const char* f :
		 {"trajectory.txt", "trajectory_online.txt", "trajectory_smoothed.txt", "keyframes.txt", "map.3Dscene",
		  "stats.json", "config_used.ini", "eval.json", "eval_online.json", "eval_smoothed.json", "dense_cloud.ply",
		  "map.ot", "map.bt", "frames.csv", "map_2d.gridmap", "map_2d.pgm", "map_2d.yaml", "map_2d.png"})
		EXPECT_TRUE(fs::exists(d / ("run/" + std::string(f)))) << f;
	// Issue 63 item 6: the progress line's rate is labelled and is the summary's fps (it counted the
	// start-up and the outputs' writing: 10.3/s against 16.5 fps).
	{
		const auto p = runTool("yesslam", {"--input", desk, "--out", d / "progress", "--detector", "none",
										   "--sequential", "--no-dense-map"});
		ASSERT_EQ(p.exitCode, 0) << p.err;
		const auto bar = p.err.rfind("9/9 (100%) ");
		ASSERT_NE(bar, std::string::npos) << p.err;
		const double shown = std::stod(p.err.substr(bar + 11));
		EXPECT_EQ(p.err.substr(p.err.find(' ', bar + 11), 4), " fps") << p.err;
		const double summary = std::stod(value(p.out, "fps"));
		EXPECT_NEAR(shown, summary, 0.05 * summary + 0.1) << p.err << p.out;
	}
	// Issue 62: each trajectory is evaluated, the smoothed one's header says it uses later frames.
	EXPECT_NO_THROW(std::stod(value(r.out, "online_ate_rmse")));
	EXPECT_NO_THROW(std::stod(value(r.out, "smoothed_ate_rmse")));
	EXPECT_NE(readText(d / "run/trajectory_smoothed.txt").find("LATER frames"), std::string::npos);
	EXPECT_EQ(readText(d / "run/trajectory.txt").find("smoothed"), std::string::npos);
	// Issue 70: the run says which rolling-shutter readout it used and where it came from, in the
	// summary, stats.json and config_used.ini; a folder whose name says nothing says "none" and warns.
	EXPECT_NE(value(r.out, "rolling shutter").find("28 ms readout, from the folder's name"), std::string::npos)
		<< r.out;
	EXPECT_NE(readText(d / "run/stats.json")
				  .find("\"rolling_shutter\": {\"readout_s\": 0.028, \"source\": \"the folder's name"),
			  std::string::npos);
	EXPECT_NE(readText(d / "run/config_used.ini").find("; [Tracking] rollingShutter = 0.028 s, from the folder's name"),
			  std::string::npos);
	EXPECT_EQ(r.err.find("rolling-shutter readout is not known"), std::string::npos) << r.err;
	{
		fs::copy(desk, d / "desk_run", fs::copy_options::recursive);
		const auto u = runTool("yesslam", {"--input", d / "desk_run", "--out", d / "unnamed", "--detector", "none",
										   "--sequential", "--quiet", "--no-dense-map"});
		ASSERT_EQ(u.exitCode, 0) << u.err;
		EXPECT_EQ(value(u.out, "rolling shutter").rfind("none", 0), 0u) << u.out;
		EXPECT_NE(u.err.find("rolling-shutter readout is not known for " + (d / "desk_run")), std::string::npos)
			<< u.err;
		EXPECT_NE(readText(d / "unnamed/stats.json").find("\"source\": \"none\""), std::string::npos);
		writeText(d / "desk_run/calibration.txt", readText(desk + "/calibration.txt") + "readout kinect1\n");
		const auto k = runTool("yesslam", {"--input", d / "desk_run", "--out", d / "named", "--detector", "none",
										   "--sequential", "--quiet", "--no-dense-map"});
		ASSERT_EQ(k.exitCode, 0) << k.err;
		EXPECT_NE(value(k.out, "rolling shutter").find("28 ms readout, from the camera file"), std::string::npos)
			<< k.out;
		EXPECT_EQ(k.err.find("readout is not known"), std::string::npos) << k.err;
	}
	// frames.csv: a header, then one row per frame with the trajectory's time, all tracked, the first a
	// keyframe, the map growing from it, and tracking times for every frame after the first.
	{
		std::istringstream csv(readText(d / "run/frames.csv"));
		std::string line;
		std::getline(csv, line);
		EXPECT_EQ(line.rfind("frame,timestamp,tracked,keyframe,", 0), 0u) << line;
		const auto traj = mrpt_yesslam::readTumTrajectory(d / "run/trajectory.txt");
		std::size_t n = 0;
		while (std::getline(csv, line))
		{
			std::vector<std::string> c;
			std::stringstream ls(line);
			for (std::string x; std::getline(ls, x, ',');) c.push_back(x);
			ASSERT_EQ(c.size(), 18u) << line;
			EXPECT_EQ(c[17], "tracked");  // where its pose comes from
			ASSERT_LT(n, traj.size());
			EXPECT_EQ(std::stoul(c[0]), n);
			EXPECT_NEAR(std::stod(c[1]), traj[n].t, 1e-6);
			EXPECT_EQ(c[2], "1");
			if (n == 0)
			{
				EXPECT_EQ(c[3], "1");
			}
			EXPECT_GE(std::stoul(c[9]), 1u);     // keyframes in the map
			EXPECT_GT(std::stoul(c[10]), 100u);  // map points
			if (n > 0)
			{
				EXPECT_GT(std::stod(c[15]), 0.0);  // track_ms
			}
			n++;
		}
		EXPECT_EQ(n, 9u);
	}
	// The dense map of real Kinect frames: a labelled cloud and an octree at the asked resolution.
	EXPECT_GT(mrpt_yesslam::readDenseCloudPly(d / "run/dense_cloud.ply").size(), 1000u);
	const auto coarse = runTool("yesslam", {"--input", desk, "--out", d / "coarse", "--detector", "none",
											"--sequential", "--quiet", "--octomap-resolution", "0.1"});
	ASSERT_EQ(coarse.exitCode, 0) << coarse.err;
	EXPECT_DOUBLE_EQ(mrpt_yesslam::CSemanticOcTree::readFile(d / "coarse/map.ot")->getResolution(), 0.1);
	const auto sparse = runTool("yesslam", {"--input", desk, "--out", d / "sparse", "--detector", "none",
											"--sequential", "--quiet", "--no-dense-map"});
	ASSERT_EQ(sparse.exitCode, 0) << sparse.err;
	EXPECT_FALSE(fs::exists(d / "sparse/map.ot"));
	EXPECT_FALSE(fs::exists(d / "sparse/dense_cloud.ply"));

	const auto help = runTool("yesslam", {"--help"});
	EXPECT_EQ(help.exitCode, 0);
	for (const char* opt : {"--input", "--out", "--config", "--detector", "--no-dynamic-filter", "--max-frames", "--gt",
							"--policy", "--no-dense-map", "--octomap-resolution"})
		EXPECT_NE(help.out.find(opt), std::string::npos) << opt;

	auto fails = [&](const std::vector<std::string>& args, const std::vector<std::string>& fragments)
	{
		const auto e = runTool("yesslam", args);
		EXPECT_EQ(e.exitCode, 1) << e.err;
		EXPECT_EQ(std::count(e.err.begin(), e.err.end(), '\n'), 1) << e.err;
		for (const auto& f : fragments) EXPECT_NE(e.err.find(f), std::string::npos) << f << " in: " << e.err;
	};
	fails({"--input", d / "missing", "--out", d / "x"}, {"yesslam: error", "missing"});
	writeText(d / "nomodel.ini", "[Detector]\nmodel = " + (d / "missing.cfg") + "\n");
	fails({"--input", desk, "--out", d / "x", "--config", d / "nomodel.ini", "--detector", "yolo"}, {"missing.cfg"});
	fails({"--input", desk, "--out", d / "x", "--max-frames", "many"}, {"--max-frames"});
	fails({"--input", desk, "--out", d / "x", "--octomap-resolution", "0"}, {"--octomap-resolution", "0.005"});
	// Finer than the cloud it is built from: refused at once (it took 85 s and 3.8 GB for 30 frames).
	fails({"--input", desk, "--out", d / "fine", "--octomap-resolution", "0.01", "--detector", "none"},
		  {"--octomap-resolution", "voxelSize 0.02"});
	EXPECT_FALSE(fs::exists(d / "fine")) << "a run that cannot start makes no output folder";
	// Issue 30 item 8: a skip past the end, options that would do nothing, a map that could not be
	// saved after the run, and a map and recording that would overwrite each other - refused at once.
	fails({"--input", desk, "--out", d / "skip", "--skip-frames", "20", "--detector", "none"},
		  {"--skip-frames 20", "holds only 9"});
	EXPECT_FALSE(fs::exists(d / "skip"));
	fails({"--input", desk, "--out", d / "x", "--speed", "2", "--detector", "none"}, {"--speed", "--realtime"});
	fails({"--input", desk, "--out", d / "x", "--width", "320", "--detector", "none"}, {"--width", "OpenNI2"});
	fails({"--input", desk, "--out", d / "x", "--save-map", "/proc/x.ysm", "--detector", "none"},
		  {"/proc/x.ysm", "takes no new files"});
	fails({"--input", desk, "--out", d / "x", "--save-map", d / "same.bin", "--record", d / "same.bin", "--detector",
		   "none"},
		  {"same file"});
	EXPECT_FALSE(fs::exists(d / "x"));
	fails({"--input", desk, "--out", d / "x", "--policy", "often", "--detector", "none"}, {"policy", "often"});
	writeText(d / "bad.ini", "[Tracking]\nmaxDepth = far\n");
	fails({"--input", desk, "--out", d / "x", "--config", d / "bad.ini"}, {"bad.ini", "maxDepth"});
	fails({"--input", desk, "--out", d / "x", "--gt", d / "bad.ini", "--detector", "none"}, {"bad.ini"});
}

TEST(Tools, ShippedConfigsRunWithTheDocumentedDetectorDefault)
{
	// Issue 18 item 3: "--config tum_fr1.ini" (or default.ini) failed with "the yolo detector needs
	// [Detector] model" although --help says the detector defaults to auto. Without a detections.txt
	// and without a model, auto picks the shipped Yolo-Fastest (issue 16 item 6).
	TempDir d("tool_shipped_cfg");
	const std::string desk = sharedFile("data/tum_fr1_desk_9frames");
	for (const char* cfg : {"default.ini", "tum_fr1.ini", "tum_fr3.ini"})
	{
		const std::string out = d / cfg;
		const auto r = runTool("yesslam", {"--input", desk, "--config",
										   std::string(YESSLAM_SOURCE_DIR) + "/share/mrpt_yesslam/config/" + cfg,
										   "--out", out, "--max-frames", "3", "--quiet"});
		EXPECT_EQ(r.exitCode, 0) << cfg << ": " << r.err;
		EXPECT_TRUE(fs::exists(out + "/trajectory.txt")) << cfg;
		std::ifstream used(out + "/config_used.ini");
		const std::string text((std::istreambuf_iterator<char>(used)), std::istreambuf_iterator<char>());
		EXPECT_NE(text.find("backend = yolo"), std::string::npos) << cfg;
		EXPECT_NE(text.find("share/mrpt_yesslam/models/yolo-fastest-1.1/yolo-fastest-1.1.cfg"), std::string::npos)
			<< cfg;
		// "auto" stays auto, its choice in a comment: the file re-run with --localize-only chooses again.
		EXPECT_NE(text.find("\nboxes = auto\n"), std::string::npos) << cfg;
		EXPECT_NE(text.find("boxes = auto chose false in this run"), std::string::npos) << cfg;
	}
}

TEST(Tools, EveryToolHasVersionAndAForgottenValueIsNamed)
{
	// Issue 18 item 5: --version on every tool (project, MRPT and OpenCV versions), and
	// "yesslam --input --out x" says that --input needs a value (it took "--out" as the input).
	for (const char* tool : {"yesslam", "yesslam-sim", "yesslam-eval", "yesslam-detect", "yesslam-render",
							 "yesslam-cloud", "yesslam-vocab", "tum2rawlog"})
	{
		const auto r = runTool(tool, {"--version"});
		EXPECT_EQ(r.exitCode, 0) << tool << ": " << r.err;
		EXPECT_EQ(r.out.rfind(std::string(tool) + " 0.", 0), 0u) << r.out;
		EXPECT_NE(r.out.find("MRPT 2.5"), std::string::npos) << r.out;
		EXPECT_NE(r.out.find("OpenCV 4"), std::string::npos) << r.out;
		EXPECT_NE(runTool(tool, {"--help"}).out.find("--version"), std::string::npos) << tool;
	}
	TempDir d("tool_forgotten_value");
	const auto r = runTool("yesslam", {"--input", "--out", d / "x"});
	EXPECT_EQ(r.exitCode, 1);
	EXPECT_NE(r.err.find("--input needs a value"), std::string::npos) << r.err;
	EXPECT_FALSE(fs::exists(d / "x"));
}

TEST(Tools, ContradictoryOrOutOfRangeOptionsSayWhy)
{
	// Issue 18 item 5: a fractional frame count, --quiet with --verbose, and --people's real range.
	TempDir d("tool_option_msgs");
	const std::string gt = sharedFile("data/tum_eval_trajectories/evo_fr2_desk_groundtruth.txt");
	const auto frac = runTool("yesslam-eval", {"--gt", gt, "--est", gt, "--rpe-unit", "f", "--rpe-delta", "1.5"});
	EXPECT_EQ(frac.exitCode, 1);
	EXPECT_NE(frac.err.find("whole number"), std::string::npos) << frac.err;
	EXPECT_EQ(runTool("yesslam-eval", {"--gt", gt, "--est", gt, "--rpe-unit", "f", "--rpe-delta", "2"}).exitCode, 0);
	const auto both = runTool("yesslam-sim", {"--out", d / "s", "--quiet", "--verbose", "--frames", "1"});
	EXPECT_EQ(both.exitCode, 1);
	EXPECT_NE(both.err.find("--quiet and --verbose"), std::string::npos) << both.err;
	EXPECT_FALSE(fs::exists(d / "s"));
	const auto people = runTool("yesslam-sim", {"--out", d / "p", "--people", "-2", "--frames", "1"});
	EXPECT_EQ(people.exitCode, 1);
	EXPECT_NE(people.err.find("-1..20"), std::string::npos) << people.err;
}

TEST(Tools, RenderAndCloudRefuseOutOfRangeValues)
{
	// Issue 18 item 2: these were accepted and gave empty or odd pictures and clouds silently.
	TempDir d("tool_ranges");
	const auto fails = [](const std::string& tool, const std::vector<std::string>& args, const std::string& fragment)
	{
		const auto r = runTool(tool, args);
		EXPECT_EQ(r.exitCode, 1) << tool << " " << fragment;
		EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
	};
	const std::string scene = d / "none.3Dscene", png = d / "x.png";
	fails("yesslam-render", {"--scene", scene, "--out", png, "--fov", "0"}, "--fov");
	fails("yesslam-render", {"--scene", scene, "--out", png, "--fov", "180"}, "--fov");
	fails("yesslam-render", {"--scene", scene, "--out", png, "--elevation", "500"}, "--elevation");
	fails("yesslam-render", {"--scene", scene, "--out", png, "--background", "255,255,255"}, "0..1");
	const std::string desk = sharedFile("data/tum_fr1_desk_9frames");
	fails("yesslam-cloud",
		  {"--input", desk, "--poses", desk + "/groundtruth.txt", "--out", d / "c.ply", "--max-depth", "-1"},
		  "--max-depth");
	EXPECT_FALSE(fs::exists(png));
}

TEST(Tools, AFailedStartLeavesNoFolderAndNoStaleEvaluation)
{
	// Issue 18 item 4 (part): a run that cannot start creates no output folder; a run without
	// ground truth in a folder an earlier evaluated run used leaves no eval.json from that run.
	TempDir d("tool_no_leftovers");
	const std::string desk = sharedFile("data/tum_fr1_desk_9frames");
	const auto bogus = runTool("yesslam", {"--input", desk, "--out", d / "run", "--detector", "bogus"});
	EXPECT_EQ(bogus.exitCode, 1);
	EXPECT_NE(bogus.err.find("auto, yolo, file, hog or none"), std::string::npos) << bogus.err;
	EXPECT_FALSE(fs::exists(d / "run"));
	const auto sim = runTool("yesslam-sim", {"--out", d / "sim", "--textures", d / "nonexistent", "--frames", "1"});
	EXPECT_EQ(sim.exitCode, 1);
	EXPECT_FALSE(fs::exists(d / "sim"));

	const auto first =
		runTool("yesslam", {"--input", desk, "--out", d / "run", "--detector", "none", "--quiet", "--max-frames", "3"});
	ASSERT_EQ(first.exitCode, 0) << first.err;
	ASSERT_TRUE(fs::exists(d / "run/eval.json"));
	// Three frames span 0.07 s: no RPE pair 1 s apart, and yesslam says so as yesslam-eval does
	// (issue 18 item 5).
	EXPECT_NE(first.err.find("yesslam: note: no RPE ("), std::string::npos) << first.err;
	// The same frames without ground truth (a copy of the folder without groundtruth.txt).
	fs::copy(desk, d / "nogt", fs::copy_options::recursive);
	fs::remove(d / "nogt/groundtruth.txt");
	const auto second = runTool(
		"yesslam", {"--input", d / "nogt", "--out", d / "run", "--detector", "none", "--quiet", "--max-frames", "3"});
	ASSERT_EQ(second.exitCode, 0) << second.err;
	EXPECT_FALSE(fs::exists(d / "run/eval.json")) << "a stale evaluation was left in place";
}

TEST(Tools, ABadVocabularyStopsTheRunBeforeItStartsAndLoopClosingCanBeTurnedOff)
{
	// Issue 13: a vocabulary named in the config that is not one (damaged, or a DBoW3 file) is one
	// line naming it, before any output; --no-loop-closure runs without looking for one, and the
	// summary and stats.json say what loop closing did.
	TempDir d("tool_vocab");
	const std::string desk = sharedFile("data/tum_fr1_desk_9frames");
	const std::string dbow3 = sharedFile("models/dbow3_vocab_slambook2/vocabulary.yml.gz");
	writeText(d / "v.ini", "[LoopClosing]\nvocabulary = " + dbow3 + "\n");
	const auto bad =
		runTool("yesslam", {"--input", desk, "--out", d / "run", "--config", d / "v.ini", "--detector", "none"});
	EXPECT_EQ(bad.exitCode, 1);
	EXPECT_NE(bad.err.find(dbow3 + ": not a yesslam vocabulary"), std::string::npos) << bad.err;
	EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
	EXPECT_FALSE(fs::exists(d / "run"));
	const auto on = runTool("yesslam", {"--input", desk, "--out", d / "on", "--detector", "none", "--quiet"});
	ASSERT_EQ(on.exitCode, 0) << on.err;
	EXPECT_NE(on.out.find("loops:           0 closed"), std::string::npos) << on.out;
	EXPECT_NE(readText(d / "on/stats.json").find("\"loop_closing\": true"), std::string::npos);
	const auto off =
		runTool("yesslam", {"--input", desk, "--out", d / "off", "--detector", "none", "--quiet", "--no-loop-closure"});
	ASSERT_EQ(off.exitCode, 0) << off.err;
	EXPECT_NE(off.out.find("loop closing off"), std::string::npos) << off.out;
	EXPECT_NE(readText(d / "off/stats.json").find("\"loop_closing\": false"), std::string::npos);
}

// The 9 real fr1/desk frames (TUM RGB-D, CC BY 4.0) copied to `dir` with the fifth frame's depth
// PNG (1305031453.505218.png) cut to a third: a sequence that fails part-way.
static void copyDeskWithATruncatedFifthDepth(const std::string& dir)
{
	fs::copy(sharedFile("data/tum_fr1_desk_9frames"), dir, fs::copy_options::recursive);
	const std::string png = dir + "/depth/1305031453.505218.png";
	const std::string bytes = readText(png);
	writeText(png, bytes.substr(0, bytes.size() / 3));
}

TEST(Tools, ARunThatFailsPartWaySaysSoInItsStats)
{
	// Issue 18 item 4: the depth PNG of the fifth frame is truncated. The run stops there with one
	// line, keeps the four frames done, and stats.json says the run is not complete, why and where;
	// a whole run says it is complete.
	TempDir d("tool_partway");
	copyDeskWithATruncatedFifthDepth(d / "seq");
	const auto r = runTool("yesslam", {"--input", d / "seq", "--out", d / "run", "--detector", "none", "--quiet"});
	EXPECT_EQ(r.exitCode, 1);
	EXPECT_NE(r.err.find("1305031453.505218.png"), std::string::npos) << r.err;
	const std::string stats = readText(d / "run/stats.json");
	EXPECT_NE(stats.find("\"complete\": false"), std::string::npos) << stats;
	EXPECT_NE(stats.find("\"stop_reason\": \"error at frame 4: "), std::string::npos) << stats;
	EXPECT_NE(stats.find("\"frames\": 4,"), std::string::npos) << stats;
	EXPECT_EQ(mrpt_yesslam::readTumTrajectory(d / "run/trajectory.txt").size(), 4u);
	const auto whole = runTool("yesslam", {"--input", sharedFile("data/tum_fr1_desk_9frames"), "--out", d / "whole",
										   "--detector", "none", "--quiet"});
	ASSERT_EQ(whole.exitCode, 0) << whole.err;
	EXPECT_NE(readText(d / "whole/stats.json").find("\"complete\": true"), std::string::npos);
}

TEST(Tools, DetectionsAndMasksAgreeWhenAFrameCannotBeRead)
{
	// Issue 18 item 4: the fifth frame's depth PNG is truncated; yesslam-detect stops there with one
	// line, and detections.txt (written anyway) covers the same frames as masks/: the first four.
	// Model: the shipped Yolo-Fastest-1.1 (darknet YOLO licence); frames: TUM fr1/desk (CC BY 4.0).
	TempDir d("detect_partway");
	copyDeskWithATruncatedFifthDepth(d / "seq");
	const std::string m = std::string(YESSLAM_SOURCE_DIR) + "/share/mrpt_yesslam/models/yolo-fastest-1.1/";
	const auto r = runTool("yesslam-detect", {"--model", m + "yolo-fastest-1.1.cfg", "--weights",
											  m + "yolo-fastest-1.1.weights", "--names", m + "coco.names", "--conf",
											  "0.1", "--input", d / "seq", "--out", d / "det", "--quiet"});
	EXPECT_EQ(r.exitCode, 1);
	EXPECT_NE(r.err.find("1305031453.505218.png"), std::string::npos) << r.err;
	ASSERT_TRUE(fs::exists(d / "det/detections.txt"));
	std::set<std::string> masks, stamps;
	for (const auto& e : fs::directory_iterator(d / "det/masks")) masks.insert(e.path().stem().string());
	EXPECT_EQ(masks.size(), 4u);
	std::istringstream lines(readText(d / "det/detections.txt"));
	for (std::string line; std::getline(lines, line);)
		if (!line.empty() && line[0] != '#') stamps.insert(line.substr(0, line.find(' ')));
	EXPECT_FALSE(stamps.empty()) << "at conf 0.1 the desk frames have detections";
	for (const auto& s : stamps) EXPECT_TRUE(masks.count(s)) << s << " has detections but no mask";
}

TEST(Tools, DetectHelpListsEveryOutputFormat)
{
	// Issue 18 item 5: --format's help listed 5 of the 8 layouts the config accepts.
	const auto help = runTool("yesslam-detect", {"--help"}).out;
	const auto line =
		help.substr(help.find("--format"), help.find('\n', help.find("--format")) - help.find("--format"));
	for (const auto& f : mrpt_yesslam::yoloOutputFormats())
		EXPECT_NE(line.find(f), std::string::npos) << f << " missing in: " << line;
	EXPECT_EQ(mrpt_yesslam::yoloOutputFormats().size(), 8u);
}

TEST(Tools, EveryToolTakesOutAndOutputAlike)
{
	// Issue 30 item 8: tum2rawlog and yesslam-oni name their output --output, the others --out; a
	// habit from one tool gave "unknown option" in the other. Both spellings work everywhere.
	TempDir d("out_alias");
	const std::string desk =
		std::filesystem::path(sharedFile("data/tum_fr1_desk_9frames/rgb.txt")).parent_path().string();
	const auto conv = runTool("tum2rawlog", {"--input", desk, "--out", d / "desk.rawlog"});
	EXPECT_EQ(conv.exitCode, 0) << conv.err;
	EXPECT_TRUE(fs::exists(d / "desk.rawlog"));
	const auto run = runTool("yesslam", {"--input", desk, "--output", d / "run", "--detector", "none", "--no-dense-map",
										 "--max-frames", "3", "--quiet"});
	EXPECT_EQ(run.exitCode, 0) << run.err;
	EXPECT_TRUE(fs::exists(d / "run/trajectory.txt"));
	const auto bogus = runTool("yesslam", {"--input", desk, "--outt", d / "x"});
	EXPECT_EQ(bogus.exitCode, 1);
	EXPECT_NE(bogus.err.find("unknown option --outt"), std::string::npos) << bogus.err;
}

TEST(Tools, BenchesMakeASimulatedSequenceAgainWhenTheSimulatorHasChanged)
{
	// The benches reuse the sequences they made (rendering is the slow part), but one made by an
	// earlier model of the world or the sensor would be measured as if it were this one's (issue
	// 27: realism changes went unmeasured until the folders were deleted by hand). meta.json and
	// yesslam-sim --model-hash carry the model's version; bench/sim_sequence.sh compares it.
	TempDir d("bench_sim_sequence");
	const auto hash = runTool("yesslam-sim", {"--model-hash"});
	ASSERT_EQ(hash.exitCode, 0) << hash.err;
	const std::string model = hash.out.substr(0, hash.out.find('\n'));
	EXPECT_EQ(model.size(), 12u) << hash.out;
	const std::string script = std::string(YESSLAM_SOURCE_DIR) + "/bench/sim_sequence.sh";
	const auto make = [&]
	{
		return runCommand(
			"bash", {"-c", "BIN='" + std::string(YESSLAM_TOOLS_DIR) + "'; source '" + script + "'; sim_sequence '" +
							   (d / "seq") + "' --preset static_office --frames 2 --no-rawlog --quiet"});
	};
	ASSERT_EQ(make().exitCode, 0);
	EXPECT_NE(readText(d / "seq/meta.json").find("\"model\": \"" + model + "\""), std::string::npos);
	// Made once: a marker left in the folder survives the next call.
	{
		std::ofstream(d / "seq/marker") << "kept";
	}
	ASSERT_EQ(make().exitCode, 0);
	EXPECT_TRUE(fs::exists(d / "seq/marker")) << "the same model and arguments: reused";
	// Made by another model (its key says so): made again.
	{
		std::ofstream(d / "seq/.bench_key") << "0123456789ab --preset static_office --frames 2 --no-rawlog --quiet";
	}
	ASSERT_EQ(make().exitCode, 0);
	EXPECT_FALSE(fs::exists(d / "seq/marker")) << "another model: made again";
	EXPECT_TRUE(fs::exists(d / "seq/meta.json"));
}

// Issue 43 item 2: a run whose map never starts is an error that says why, and a depth scale that
// puts the scene out of an RGB-D camera's range is named (the real fr1/desk frames, TUM RGB-D,
// CC BY 4.0).
TEST(Tools, ARunWhoseMapNeverStartsFailsAndAnImplausibleDepthScaleIsNamed)
{
	TempDir d("tool_nomap");
	const std::string desk = sharedFile("data/tum_fr1_desk_9frames");
	// Depth declared 500 units a metre for TUM's 5000: the scene seems 10x farther, beyond what
	// tracking uses; no map starts.
	writeText(d / "k500.txt", "517.3 516.5 318.6 255.3 640 480 500\n");
	const auto far = runTool(
		"yesslam", {"--input", desk, "--out", d / "far", "--detector", "none", "--quiet", "--camera", d / "k500.txt"});
	EXPECT_EQ(far.exitCode, 1) << far.out;
	EXPECT_NE(far.err.find("no map was made"), std::string::npos) << far.err;
	EXPECT_NE(far.err.find("depth scale"), std::string::npos) << far.err;
	EXPECT_EQ(std::count(far.err.begin(), far.err.end(), '\n'), 1) << far.err;
	// 1000 for 5000: 5x farther, a map starts (the nearest desk is within reach), and the run says
	// why it should not be trusted.
	writeText(d / "k1000.txt", "517.3 516.5 318.6 255.3 640 480 1000\n");
	const auto five = runTool("yesslam", {"--input", desk, "--out", d / "five", "--detector", "none", "--quiet",
										  "--camera", d / "k1000.txt"});
	EXPECT_EQ(five.exitCode, 0) << five.err;
	EXPECT_NE(five.err.find("farther than RGB-D cameras measure well"), std::string::npos) << five.err;
	// All-black frames without depth: the same, with their own reason.
	fs::copy(desk, d / "black", fs::copy_options::recursive);
	for (const auto& e : fs::directory_iterator(d / "black/depth"))
		cv::imwrite(e.path().string(), cv::Mat::zeros(480, 640, CV_16U));
	for (const auto& e : fs::directory_iterator(d / "black/rgb"))
		cv::imwrite(e.path().string(), cv::Mat::zeros(480, 640, CV_8UC3));
	const auto black =
		runTool("yesslam", {"--input", d / "black", "--out", d / "blackrun", "--detector", "none", "--quiet"});
	EXPECT_EQ(black.exitCode, 1);
	EXPECT_NE(black.err.find("no map was made"), std::string::npos) << black.err;
	EXPECT_NE(black.err.find("no frame has any depth"), std::string::npos) << black.err;
	// 5x too small (25000 for 5000): the map starts, a 5x smaller one, and the run says why it
	// should not be trusted.
	writeText(d / "k25000.txt", "517.3 516.5 318.6 255.3 640 480 25000\n");
	const auto near = runTool("yesslam", {"--input", desk, "--out", d / "near", "--detector", "none", "--quiet",
										  "--camera", d / "k25000.txt"});
	EXPECT_EQ(near.exitCode, 0) << near.err;
	EXPECT_NE(near.err.find("yesslam: warning: the median depth is 0.2"), std::string::npos) << near.err;
	EXPECT_NE(near.err.find("nearer than RGB-D cameras measure"), std::string::npos) << near.err;
	// Issue 63 item 6: a scale no camera can have (100x either way: a median of 1.5 cm or 150 m) stops
	// the run at its fifth frame with depth, in one line naming the depth scale, and nothing says complete.
	for (const char* scale : {"500000", "50"})
	{
		writeText(d / "kbad.txt", std::string("517.3 516.5 318.6 255.3 640 480 ") + scale + "\n");
		const auto bad = runTool("yesslam", {"--input", desk, "--out", d / "bad", "--detector", "none", "--quiet",
											 "--camera", d / "kbad.txt"});
		EXPECT_EQ(bad.exitCode, 1) << bad.out;
		EXPECT_NE(bad.err.find("the median depth of its first 5 frames with depth is"), std::string::npos) << bad.err;
		EXPECT_NE(bad.err.find("the depth scale is wrong"), std::string::npos) << bad.err;
		EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
		EXPECT_NE(readText(d / "bad/stats.json").find("\"complete\": false"), std::string::npos);
	}
	// The right scale: no such warning, and stats.json has the typical depth (fr1/desk: 0.74-2.41 m).
	const auto right = runTool("yesslam", {"--input", desk, "--out", d / "right", "--detector", "none", "--quiet"});
	ASSERT_EQ(right.exitCode, 0) << right.err;
	EXPECT_EQ(right.err.find("median depth"), std::string::npos) << right.err;
	const std::string stats = readText(d / "right/stats.json");
	const auto p = stats.find("\"typical_depth_m\": ");
	ASSERT_NE(p, std::string::npos) << stats;
	const double typical = std::stod(stats.substr(p + 19));
	EXPECT_GT(typical, 0.74);
	EXPECT_LT(typical, 2.41);
}

// Issue 43 items 4, 6, 7, 8: a reused folder keeps no stale dense map, unpaired colour images are
// counted and named, a skip of every frame is refused, a camera file without a size takes the
// images' and an option that cannot apply is not recorded as applied.
TEST(Tools, ReusedFoldersUnpairedImagesSkipsAndCameraFilesSayWhatHappened)
{
	TempDir d("tool_issue43");
	const std::string desk = sharedFile("data/tum_fr1_desk_9frames");
	const auto full = runTool("yesslam", {"--input", desk, "--out", d / "run", "--detector", "none", "--quiet"});
	ASSERT_EQ(full.exitCode, 0) << full.err;
	for (const char* f : {"dense_cloud.ply", "map.ot", "map.bt"})
		ASSERT_TRUE(fs::exists(d / ("run/" + std::string(f)))) << f;
	const auto sparse =
		runTool("yesslam", {"--input", desk, "--out", d / "run", "--detector", "none", "--quiet", "--no-dense-map"});
	ASSERT_EQ(sparse.exitCode, 0) << sparse.err;
	for (const char* f : {"dense_cloud.ply", "map.ot", "map.bt"})
		EXPECT_FALSE(fs::exists(d / ("run/" + std::string(f)))) << f << " of the earlier run survived";

	// Colour and depth 9-15 ms apart (associations.txt): with maxDiff 13.4 ms only some pair.
	std::size_t unpaired = 0;
	{
		std::istringstream assoc(readText(desk + "/associations.txt"));
		for (std::string l; std::getline(assoc, l);)
		{
			double a = 0, b = 0;
			std::string fa;
			if (l.empty() || l[0] == '#' || !(std::istringstream(l) >> a >> fa >> b)) continue;
			unpaired += std::abs(b - a) >= 0.0134;
		}
	}
	ASSERT_GT(unpaired, 0u);
	ASSERT_LT(unpaired, 8u);
	writeText(d / "tight.ini", "[Input]\nmaxDiff = 0.0134\n[Tracking]\ndepthMoment = true\n");
	const auto tight = runTool("yesslam", {"--input", desk, "--out", d / "tight", "--detector", "none", "--quiet",
										   "--config", d / "tight.ini"});
	ASSERT_EQ(tight.exitCode, 0) << tight.err;
	EXPECT_NE(tight.err.find("yesslam: warning: " + std::to_string(unpaired) + " colour images have no depth image"),
			  std::string::npos)
		<< tight.err;
	EXPECT_NE(tight.err.find("maxDiff 0.0134 s"), std::string::npos) << tight.err;
	EXPECT_NE(readText(d / "tight/stats.json").find("\"unpaired_frames\": " + std::to_string(unpaired) + ","),
			  std::string::npos);
	// Issue 42 item 4: a TUM folder stamps its depth images (depthMoment applies: no word of it),
	// and its Kinect v1 (a freiburg name beside calibration.txt) has the known 28 ms readout.
	EXPECT_EQ(tight.err.find("depthMoment"), std::string::npos) << tight.err;
	EXPECT_NE(readText(d / "tight/config_used.ini").find("rollingShutter = 0.028\n"), std::string::npos);

	// --skip-frames 9 of 9 frames leaves none: refused like 10, before any output.
	const auto skip =
		runTool("yesslam", {"--input", desk, "--out", d / "skip", "--skip-frames", "9", "--detector", "none"});
	expectCleanFailure(skip, {"--skip-frames 9", "holds only 9 frames"});
	EXPECT_FALSE(fs::exists(d / "skip"));

	// A camera file of four numbers: the images' size, and an error about a size names the images.
	writeText(d / "k4.txt", "517.3 516.5 318.6 255.3\n");
	const auto four = runTool(
		"yesslam", {"--input", desk, "--out", d / "four", "--detector", "none", "--quiet", "--camera", d / "k4.txt"});
	EXPECT_EQ(four.exitCode, 0) << four.err;
	// A camera file that gives no readout: the camera's shutter is not known, so not corrected;
	// one that gives it (a line of one number, seconds) is corrected by that.
	EXPECT_NE(readText(d / "four/config_used.ini").find("rollingShutter = 0\n"), std::string::npos);
	writeText(d / "k5.txt", "517.3 516.5 318.6 255.3 640 480\n0.2624 -0.9531 -0.0054 0.0026 1.1633\n0.02\n");
	const auto five = runTool("yesslam", {"--input", desk, "--out", d / "five", "--detector", "none", "--quiet",
										  "--no-dense-map", "--camera", d / "k5.txt"});
	EXPECT_EQ(five.exitCode, 0) << five.err;
	EXPECT_NE(readText(d / "five/config_used.ini").find("rollingShutter = 0.02\n"), std::string::npos);
	writeText(d / "k4out.txt", "517.3 516.5 900 255.3\n");
	const auto outside = runTool("yesslam", {"--input", desk, "--out", d / "outside", "--detector", "none", "--quiet",
											 "--camera", d / "k4out.txt"});
	expectCleanFailure(outside, {"k4out.txt", "principal point", "640x480 images"});

	// --camera on a rawlog does nothing: said, and not recorded in config_used.ini.
	const auto conv = runTool("tum2rawlog", {"--input", desk, "--out", d / "desk.rawlog"});
	ASSERT_EQ(conv.exitCode, 0) << conv.err;
	writeText(d / "moment.ini", "[Tracking]\ndepthMoment = true\n");
	const auto raw = runTool("yesslam", {"--input", d / "desk.rawlog", "--out", d / "raw", "--detector", "none",
										 "--quiet", "--camera", "fr2", "--config", d / "moment.ini"});
	ASSERT_EQ(raw.exitCode, 0) << raw.err;
	// A rawlog has no depth-image stamps of its own (depthMoment cannot apply: said); its readout is
	// the one tum2rawlog wrote beside it (desk_camera.txt: the fr1 folder's Kinect, 28 ms), not
	// --camera's, which is for folders and OpenNI2 input.
	EXPECT_NE(raw.err.find("[Tracking] depthMoment does nothing for " + (d / "desk.rawlog")), std::string::npos)
		<< raw.err;
	EXPECT_NE(readText(d / "raw/config_used.ini").find("rollingShutter = 0.028\n"), std::string::npos);
	EXPECT_NE(readText(d / "raw/config_used.ini").find("from the recording's camera file"), std::string::npos);
	EXPECT_NE(raw.err.find("--camera) 'fr2' is for TUM folders and OpenNI2 input and was not used"), std::string::npos)
		<< raw.err;
	EXPECT_EQ(readText(d / "raw/config_used.ini").find("camera = fr2"), std::string::npos);

	// --record of a TUM folder keeps its ground truth beside the recording, where a run finds it.
	const auto rec = runTool("yesslam", {"--input", desk, "--out", d / "rec", "--detector", "none", "--quiet",
										 "--no-dense-map", "--record", d / "rec.rawlog"});
	ASSERT_EQ(rec.exitCode, 0) << rec.err;
	EXPECT_EQ(readText(d / "rec_groundtruth.txt"), readText(desk + "/groundtruth.txt"));
	const auto replay = runTool("yesslam", {"--input", d / "rec.rawlog", "--out", d / "replay", "--detector", "none",
											"--quiet", "--no-dense-map"});
	ASSERT_EQ(replay.exitCode, 0) << replay.err;
	EXPECT_TRUE(fs::exists(d / "replay/eval.json"));
}

// Issue 43 item 5: JSON to /dev/stdout follows the key: value lines, redirected to a file or a pipe.
TEST(Tools, EvalJsonToStdoutKeepsTheLinesBeforeIt)
{
	const std::string gt = sharedFile(kTraj + "evo_fr2_desk_groundtruth.txt"),
					  est = sharedFile(kTraj + "evo_fr2_desk_ORB.txt");
	const auto file = runTool("yesslam-eval", {"--gt", gt, "--est", est, "--json", "/dev/stdout"});
	ASSERT_EQ(file.exitCode, 0) << file.err;
	EXPECT_EQ(value(file.out, "ate_pairs"), "2223") << file.out;
	EXPECT_NE(file.out.find("\"ate_rmse\":"), std::string::npos) << file.out;
	EXPECT_LT(file.out.find("ate_rmse: "), file.out.find("\"ate_rmse\":")) << "the lines first, then the JSON";
	const auto pipe = runCommand("sh", {"-c", std::string(YESSLAM_TOOLS_DIR) + "/yesslam-eval --gt '" + gt +
												  "' --est '" + est + "' --json /dev/stdout | cat"});
	ASSERT_EQ(pipe.exitCode, 0) << pipe.err;
	EXPECT_EQ(value(pipe.out, "ate_pairs"), "2223") << pipe.out;
	EXPECT_NE(pipe.out.find("\"ate_rmse\":"), std::string::npos) << pipe.out;
}

// Issue 39 item 2: the depth error grows faster than z^2 ([Camera] depthNoiseExponent). The last
// 100 frames of the real Bonn crowd slice (people crossing close, the camera panning over walls
// 2-5 m away; Bonn RGB-D Dynamic Dataset, CC BY-NC 4.0, test data only:
// ../shared/data/bonn_crowd_dev/SOURCE.md), run from there as a sequence of its own with the
// default configuration and the shipped detector: 17.3 mm with the z^2.5 model, 46.6 mm when far
// depths were trusted as z^2 (2.3 cm at 3 m instead of 3.9 cm: the far walls' biased depths
// pulled the poses).
TEST(Tools, FarDepthIsWeighedAsTheRealSensorsErrorGrows)
{
	TempDir d("tool_far_depth");
	const auto r =
		runTool("yesslam", {"--input", sharedFile("data/bonn_crowd_dev"), "--out", d / "run", "--quiet", "--sequential",
							"--no-dense-map", "--skip-frames", "150", "--max-frames", "100"});
	ASSERT_EQ(r.exitCode, 0) << r.err;
	EXPECT_EQ(value(r.out, "frames"), "100") << r.out;
	EXPECT_LT(std::stod(value(r.out, "ate_rmse")), 0.025) << r.out;
}

// Issue 39 item 2: the pose does not zig-zag along what far points leave free. The first 100
// frames of the real Bonn crowd slice (Xtion, the camera panning over walls 2-5 m away; Bonn RGB-D
// Dynamic Dataset, CC BY-NC 4.0, test data only: ../shared/data/bonn_crowd_dev/SOURCE.md), default
// configuration, shipped detector: with the motion model's prediction as a weak term of the pose
// solve the estimate steps as the camera does (jitter 4.4 mm against a true step of 3.9 mm, the
// issue's target 1.5 x); without it 5.8 mm, and the ATE no better. Both judged on trajectory.txt,
// which is never smoothed over later frames (trajectory_smoothed.txt is).
TEST(Tools, ThePoseDoesNotZigZagAlongWhatFarPointsLeaveFree)
{
	TempDir d("tool_zigzag");
	writeText(d / "held.ini", "[Tracking]\n");
	writeText(d / "none.ini", "[Tracking]\nmotionPriorSigma = 0\n");
	const auto run = [&](const std::string& name, const std::vector<std::string>& extra)
	{
		std::vector<std::string> args{"--input",
									  sharedFile("data/bonn_crowd_dev"),
									  "--out",
									  d / name,
									  "--quiet",
									  "--sequential",
									  "--no-dense-map",
									  "--max-frames",
									  "100"};
		args.insert(args.end(), extra.begin(), extra.end());
		const auto r = runTool("yesslam", args);
		EXPECT_EQ(r.exitCode, 0) << r.err;
		return std::make_tuple(std::stod(value(r.out, "jitter_median")), std::stod(value(r.out, "step_gt_median")),
							   std::stod(value(r.out, "ate_rmse")));
	};
	const auto [jitter, step, ate] = run("held", {"--config", d / "held.ini"});
	const auto [jitterFree, stepFree, ateFree] = run("free", {"--config", d / "none.ini"});
	EXPECT_LT(jitter, 1.5 * step) << "the issue's target";
	EXPECT_LT(jitter, 0.85 * jitterFree);
	EXPECT_LT(ate, ateFree + 0.001);
}

// Issue 39 item 0: a departure from the paper stays only where it helps on the real cameras. The
// second half of the real Bonn crowd slice (people from its first frame, often filling the view;
// Bonn RGB-D Dynamic Dataset, CC BY-NC 4.0, test data only: ../shared/data/bonn_crowd_dev/SOURCE.md),
// default configuration, shipped detector. With the geometric check's box part (keypoints in a
// person's box but outside the mask uncertain, [GeometricCheck] boxes = true), 12 frames were lost
// where people filled the view and the ATE was 21.3 mm; without it, while mapping (boxes = auto),
// the mask and the mover check keep the people out, every frame is tracked, 17.7 mm. Both judged
// on trajectory.txt, which is never smoothed (smoothing evens out part of what lost frames cost).
TEST(Tools, WhilePeopleFillTheViewTheBackgroundBetweenThemStillCarriesThePose)
{
	TempDir d("tool_boxes");
	writeText(d / "auto.ini", "[Tracking]\n");
	writeText(d / "boxes.ini", "[GeometricCheck]\nboxes = true\n");
	const auto run = [&](const std::string& name, const std::vector<std::string>& extra)
	{
		std::vector<std::string> args{"--input",
									  sharedFile("data/bonn_crowd_dev"),
									  "--out",
									  d / name,
									  "--quiet",
									  "--sequential",
									  "--no-dense-map",
									  "--skip-frames",
									  "125",
									  "--max-frames",
									  "125"};
		args.insert(args.end(), extra.begin(), extra.end());
		const auto r = runTool("yesslam", args);
		EXPECT_EQ(r.exitCode, 0) << r.err;
		EXPECT_EQ(value(r.out, "frames"), "125") << r.out;
		return std::make_pair(r.out, std::stod(value(r.out, "ate_rmse")));
	};
	const auto [out, ate] = run("auto", {"--config", d / "auto.ini"});
	const auto [outBoxes, ateBoxes] = run("boxes", {"--config", d / "boxes.ini"});
	EXPECT_EQ(value(out, "tracked").substr(0, 4), "125 ") << out;
	EXPECT_LT(ate, ateBoxes - 0.002) << out << outBoxes;
	EXPECT_NE(readText(d / "auto/config_used.ini").find("boxes = auto chose false in this run"), std::string::npos)
		<< "config_used.ini: mapping runs without the box part";
}

// Issue 43 item 3: frames.csv marks every keyframe (Algorithm 1 picks earlier frames too), and
// with [System] keyFrameFramePose = keyframe trajectory.txt gives a keyframe's frame the
// keyframe's own final pose. The real Bonn crowd frames (Bonn RGB-D Dynamic Dataset, CC BY-NC 4.0,
// test data only: ../shared/data/bonn_crowd_dev/SOURCE.md).
TEST(Tools, EveryKeyFrameIsMarkedAndTheTrajectoryCanAgreeWithTheKeyFrames)
{
	TempDir d("tool_kf_agree");
	writeText(d / "own.ini", "[System]\nkeyFrameFramePose = keyframe\n");
	const auto r =
		runTool("yesslam", {"--input", sharedFile("data/bonn_crowd_dev"), "--out", d / "run", "--detector", "none",
							"--quiet", "--sequential", "--max-frames", "80", "--config", d / "own.ini"});
	ASSERT_EQ(r.exitCode, 0) << r.err;
	std::istringstream csv(readText(d / "run/frames.csv"));
	std::string line;
	std::getline(csv, line);
	std::set<double> marked;
	while (std::getline(csv, line))
	{
		std::vector<std::string> c;
		std::stringstream ls(line);
		for (std::string x; std::getline(ls, x, ',');) c.push_back(x);
		ASSERT_EQ(c.size(), 18u) << line;
		if (c[3] == "1") marked.insert(std::stod(c[1]));
	}
	const auto inserted = std::stoul(value(r.out, "keyframes").substr(0, value(r.out, "keyframes").find(' ')));
	EXPECT_GE(inserted, 4u) << r.out;
	EXPECT_EQ(marked.size(), inserted) << r.out;
	const auto traj = mrpt_yesslam::readTumTrajectory(d / "run/trajectory.txt");
	const auto kfs = mrpt_yesslam::readTumTrajectory(d / "run/keyframes.txt");
	ASSERT_GE(kfs.size(), 3u);
	std::size_t checked = 0;
	for (const auto& k : kfs)
	{
		EXPECT_TRUE(marked.count(k.t) ||
					std::any_of(marked.begin(), marked.end(), [&](double t) { return std::abs(t - k.t) < 1e-6; }))
			<< k.t;
		for (const auto& p : traj)
			if (std::abs(p.t - k.t) < 1e-6)
			{
				EXPECT_NEAR(p.tx, k.tx, 1e-6) << k.t;
				EXPECT_NEAR(p.ty, k.ty, 1e-6) << k.t;
				EXPECT_NEAR(p.tz, k.tz, 1e-6) << k.t;
				EXPECT_NEAR(std::abs(p.qx * k.qx + p.qy * k.qy + p.qz * k.qz + p.qw * k.qw), 1.0, 1e-6) << k.t;
				checked++;
			}
	}
	EXPECT_EQ(checked, kfs.size());
	// Issue 42 item 4: a Bonn folder's marker ground truth is recognised without --gt-format, and
	// the run says how it took it (as TUM camera poses its RPE read about 11 deg/s).
	EXPECT_NE(value(r.out, "ground truth").find("Bonn RGB-D Dynamic marker poses"), std::string::npos) << r.out;
	EXPECT_LT(std::stod(value(r.out, "rpe_rot_rmse_deg")), 3.0) << r.out;
}

// Issue 43 item 9: yesslam-sim --no-rawlog leaves no rawlog folder and does not announce one;
// progress totals follow --max-frames; no "-0.000000000" in the trajectory files.
TEST(Tools, SmallThingsANewUserNoticed)
{
	TempDir d("tool_small43");
	const auto sim =
		runTool("yesslam-sim", {"--out", d / "sim", "--preset", "static_office", "--frames", "2", "--no-rawlog"});
	ASSERT_EQ(sim.exitCode, 0) << sim.err;
	EXPECT_FALSE(fs::exists(d / "sim/sequence_Images"));
	EXPECT_FALSE(fs::exists(d / "sim/sequence.rawlog"));
	EXPECT_EQ(sim.out.find("sequence.rawlog"), std::string::npos) << sim.out;
	const std::string desk = sharedFile("data/tum_fr1_desk_9frames");
	const auto oni = runTool("yesslam-oni", {"--input", desk, "--output", d / "x.oni", "--max-frames", "3"});
	ASSERT_EQ(oni.exitCode, 0) << oni.err;
	EXPECT_NE(oni.err.find(" 3/3 "), std::string::npos) << oni.err;
	EXPECT_EQ(oni.err.find("/9 "), std::string::npos) << oni.err;
	const auto cloud = runTool("yesslam-cloud", {"--input", desk, "--poses", desk + "/groundtruth.txt", "--out",
												 d / "c.3Dscene", "--max-frames", "3"});
	ASSERT_EQ(cloud.exitCode, 0) << cloud.err;
	EXPECT_NE(cloud.err.find(" 3/3 "), std::string::npos) << cloud.err;
	const auto run = runTool(
		"yesslam", {"--input", desk, "--out", d / "run", "--detector", "none", "--quiet", "--world-frame", "optical"});
	ASSERT_EQ(run.exitCode, 0) << run.err;
	for (const char* f : {"trajectory.txt", "keyframes.txt", "trajectory_online.txt"})
		EXPECT_EQ(readText(d / ("run/" + std::string(f))).find("-0.000000000"), std::string::npos) << f;
}

// Issue 39 item 1: a person the detector misses, close to the camera, must not carry the pose. The
// simulated crowd (yesslam-sim, real-sensor model, seed 1) with the shipped Yolo-Fastest, which
// misses most simulated people: at frames 547-551 a walker 0.9 m away fills a third of the view
// and the keyframe before made map points on it. Before, the mover check's candidate was the worst
// of the groups that moved at least moverShift: the walker's body group fitted the others' pose
// worst but moved a few millimetres, and a wall 3.8 m away, bent by it, was left out instead; the
// frames were reported tracked 34-80 mm off. Now the worst group is the candidate, and when it
// moved too little the others are tested again without it (the walker's legs then leave, and the
// body after them): every frame of the passage stays within 25 mm of the truth after the run's
// alignment (it was 34-80 mm; the run's median is 6 mm).
TEST(Tools, AnUndetectedPersonCloseToTheCameraDoesNotCarryThePose)
{
	TempDir d("tool_undetected_close");
	mrpt_yesslam::TSimOptions so;  // yesslam-sim --preset crowd --real-sensor --seed 1 --frames 560 --depth-offset 0
	so.preset = "crowd";
	so.realSensor = true;
	so.seed = 1;
	so.frames = 560;
	// The sequence these figures are of: colour and depth taken together (the crowd preset has had
	// the real Bonn frames' colour/depth offset since 2026-11-29; this test is about the walker).
	so.depthOffsetMs = 0;
	const std::string seq = cachedSequence("tools_crowd_real_sensor_s1_560_sync", so);
	const auto run = runTool("yesslam", {"--input", seq, "--out", d / "run", "--detector", "yolo", "--quiet",
										 "--sequential", "--no-dense-map", "--no-loop-closure"});
	ASSERT_EQ(run.exitCode, 0) << run.err;
	// The online poses (what tracking reported then), aligned to the truth over the whole run.
	const auto ev = runTool("yesslam-eval", {"--gt", seq + "/groundtruth.txt", "--est", d / "run/trajectory_online.txt",
											 "--errors", d / "errors.csv"});
	ASSERT_EQ(ev.exitCode, 0) << ev.err;
	std::istringstream csv(readText(d / "errors.csv"));
	std::string line;
	std::getline(csv, line);
	std::vector<double> err;
	while (std::getline(csv, line)) err.push_back(std::stod(line.substr(line.find(',') + 1)));
	ASSERT_EQ(err.size(), 560u);
	for (std::size_t k = 540; k < 560; k++) EXPECT_LT(err[k], 0.025) << "frame " << k << " (online pose)";
}
