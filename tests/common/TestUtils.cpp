#include "TestUtils.h"

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

#ifdef YESSLAM_TSAN
// ThreadSanitizer builds only: OpenCV's parallel_for_ runs on Debian's libtbb, which is not built
// with TSan, so TSan cannot see how TBB hands work between its threads and reports the chunks of
// one parallel_for_ (the simulator's ray caster) as racing. With one OpenCV thread parallel_for_
// runs inline. Every thread of ours (worker pool, mapping stage, asynchronous detector, prefetching
// reader, PNG writers) is still checked.
namespace
{
[[maybe_unused]] const bool kOpenCvInline = (cv::setNumThreads(1), true);
}
#endif

namespace yesslam_test
{
std::string sharedFile(const std::string& relative)
{
	const fs::path p = fs::path(YESSLAM_SHARED_DIR) / relative;
	if (!fs::exists(p))
		throw std::runtime_error("required shared test file is missing: " + p.string() +
								 " (the tests need ../shared beside the repository)");
	return p.string();
}

TempDir::TempDir(const std::string& tag)
{
	static std::atomic<int> counter{0};
	const fs::path base = fs::temp_directory_path() / "yesslam_tests";
	fs::create_directories(base);
	path_ = (base / (tag + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++))).string();
	fs::remove_all(path_);
	fs::create_directories(path_);
}

TempDir::~TempDir()
{
	std::error_code ec;
	fs::remove_all(path_, ec);
}

std::string readText(const std::string& path)
{
	std::ifstream f(path, std::ios::binary);
	std::stringstream ss;
	ss << f.rdbuf();
	return ss.str();
}

namespace
{
std::string quote(const std::string& s)
{
	std::string q = "'";
	for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
	return q + "'";
}
}  // namespace

RunResult runTool(const std::string& tool, const std::vector<std::string>& args)
{
	return runCommand(std::string(YESSLAM_TOOLS_DIR) + "/" + tool, args);
}

RunResult runCommand(const std::string& program, const std::vector<std::string>& args)
{
	TempDir tmp("run");
	std::string cmd = quote(program);
	for (const auto& a : args) cmd += " " + quote(a);
	cmd += " >" + quote(tmp / "out") + " 2>" + quote(tmp / "err") + " </dev/null";
	const int st = std::system(cmd.c_str());
	RunResult r;
	r.exitCode = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
	r.out = readText(tmp / "out");
	r.err = readText(tmp / "err");
	return r;
}

std::vector<SyntheticFrame> makeSyntheticFrames(int n, int w, int h)
{
	std::vector<SyntheticFrame> frames;
	std::mt19937 rng(42);
	for (int k = 0; k < n; k++)
	{
		SyntheticFrame f;
		f.tRgb = 1000.0 + k / 30.0;
		f.tDepth = f.tRgb + 0.004;  // depth 4 ms after colour, well inside the 0.02 s window
		f.bgr = cv::Mat(h, w, CV_8UC3);
		f.depth = cv::Mat(h, w, CV_16UC1);
		for (int y = 0; y < h; y++)
			for (int x = 0; x < w; x++)
			{
				f.bgr.at<cv::Vec3b>(y, x) =
					cv::Vec3b(static_cast<uchar>((x * 4 + k) & 255), static_cast<uchar>((y * 5) & 255),
							  static_cast<uchar>(rng() & 255));
				f.depth.at<uint16_t>(y, x) = static_cast<uint16_t>(5001 + 7 * x + 3 * y + k);
			}
		f.depth.at<uint16_t>(0, 0) = 0;      // an invalid pixel
		f.depth.at<uint16_t>(1, 1) = 65535;  // the largest raw value
		frames.push_back(std::move(f));
	}
	return frames;
}

void writeText(const std::string& path, const std::string& content)
{
	std::ofstream f(path, std::ios::binary);
	f << content;
	if (!f) throw std::runtime_error("cannot write " + path);
}

void writeTumFolder(const std::string& folder, const std::vector<SyntheticFrame>& frames, bool withGroundTruth,
					bool withCalibration)
{
	fs::create_directories(fs::path(folder) / "rgb");
	fs::create_directories(fs::path(folder) / "depth");
	std::string rgb = "# color images\n# timestamp filename\n", depth = "# depth maps\n# timestamp filename\n",
				gt = "# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n";
	char buf[256];
	for (std::size_t k = 0; k < frames.size(); k++)
	{
		const auto& f = frames[k];
		std::snprintf(buf, sizeof(buf), "%.6f", f.tRgb);
		const std::string rn = std::string("rgb/") + buf + ".png";
		rgb += std::string(buf) + " " + rn + "\n";
		std::snprintf(buf, sizeof(buf), "%.6f", f.tDepth);
		const std::string dn = std::string("depth/") + buf + ".png";
		depth += std::string(buf) + " " + dn + "\n";
		cv::imwrite((fs::path(folder) / rn).string(), f.bgr);
		cv::imwrite((fs::path(folder) / dn).string(), f.depth);
		std::snprintf(buf, sizeof(buf), "%.4f %.4f 0.0000 1.5000 0 0 0 1\n", f.tRgb, 0.01 * k);
		gt += buf;
	}
	writeText((fs::path(folder) / "rgb.txt").string(), rgb);
	writeText((fs::path(folder) / "depth.txt").string(), depth);
	if (withGroundTruth) writeText((fs::path(folder) / "groundtruth.txt").string(), gt);
	if (withCalibration && !frames.empty())
	{
		std::snprintf(buf, sizeof(buf), "# fx fy cx cy width height depth_scale\n535.4 539.2 %.1f %.1f %d %d 5000\n",
					  frames[0].bgr.cols / 2.0, frames[0].bgr.rows / 2.0, frames[0].bgr.cols, frames[0].bgr.rows);
		writeText((fs::path(folder) / "calibration.txt").string(), buf);
	}
}

mrpt::img::TCamera fr3Camera()
{
	mrpt::img::TCamera K;
	K.ncols = 640;
	K.nrows = 480;
	K.fx(535.4);
	K.fy(539.2);
	K.cx(320.1);
	K.cy(247.6);
	return K;
}

std::shared_ptr<mrpt_yesslam::TFrame> observeWorld(std::size_t id, const mrpt::poses::CPose3D& Twc,
												   const std::vector<mrpt::math::TPoint3D>& world,
												   std::vector<mrpt_yesslam::TPointId> ids, std::mt19937& rng,
												   int octave)
{
	auto f = std::make_shared<mrpt_yesslam::TFrame>();
	f->id = id;
	f->timestamp = static_cast<double>(id);
	f->camera = fr3Camera();
	f->pose = Twc;
	f->tracked = true;
	f->features.descriptors = cv::Mat(0, 32, CV_8U);
	std::uniform_int_distribution<int> byte(0, 255);
	const mrpt::poses::CPose3D Tcw = -Twc;
	for (std::size_t j = 0; j < world.size(); j++)
	{
		double x, y, z;
		Tcw.composePoint(world[j].x, world[j].y, world[j].z, x, y, z);
		cv::KeyPoint kp;
		kp.pt = {static_cast<float>(f->camera.fx() * x / z + f->camera.cx()),
				 static_cast<float>(f->camera.fy() * y / z + f->camera.cy())};
		kp.octave = octave;
		f->features.keypoints.push_back(kp);
		f->features.depth.push_back(static_cast<float>(z));
		f->features.dynamic.push_back(false);
		cv::Mat d(1, 32, CV_8U);
		for (int b = 0; b < 32; b++) d.at<uchar>(b) = static_cast<uchar>(byte(rng));
		f->features.descriptors.push_back(d);
		f->colors.emplace_back(100, 100, 100);
	}
	f->mapPoints = std::move(ids);
	return f;
}
std::string cachedSequence(const std::string& name, const mrpt_yesslam::TSimOptions& opts)
{
	namespace fs = std::filesystem;
	// Named by the simulator's model too: a build folder's cache outlives the sources that made it,
	// and a sequence of another model is not this one's.
	const std::string path =
		std::string(YESSLAM_TEST_CACHE_DIR) + "/" + name + "-" + mrpt_yesslam::simulatorModelHash();
	if (!fs::exists(path + "/meta.json"))
	{
		fs::create_directories(YESSLAM_TEST_CACHE_DIR);
		// This sequence of another model (or of before models named the folders) is of no more use.
		std::vector<fs::path> stale;
		std::error_code listEc;
		for (const auto& e : fs::directory_iterator(YESSLAM_TEST_CACHE_DIR, listEc))
		{
			const std::string n = e.path().filename().string(), hash = mrpt_yesslam::simulatorModelHash();
			const bool otherModel = n.size() == name.size() + 1 + hash.size() &&
									n.compare(0, name.size() + 1, name + "-") == 0 &&
									n.find_first_not_of("0123456789abcdef", name.size() + 1) == std::string::npos;
			if ((n == name || otherModel) && e.path().string() != path) stale.push_back(e.path());
		}
		for (const auto& p : stale) fs::remove_all(p, listEc);
		const std::string tmp = path + ".tmp." + std::to_string(::getpid());
		mrpt_yesslam::TSimOptions o = opts;
		o.outDir = tmp;
		o.writeRawlog = false;
		mrpt_yesslam::runSimulation(o);
		std::error_code ec;
		fs::rename(tmp, path, ec);
		if (ec) fs::remove_all(tmp);  // another process was first
	}
	return path;
}

std::string walkingSequence60()
{
	mrpt_yesslam::TSimOptions o;
	o.preset = "walking_xyz";
	o.frames = 60;
	return cachedSequence("system_walking_xyz_60", o);
}

std::string walkingOniRecording(const std::string& dir)
{
	const std::string seq = walkingSequence60(), oni = dir + "/walking.oni";
	const auto r = runTool("yesslam-oni", {"--input", seq, "--output", oni, "--quiet"});
	EXPECT_EQ(r.exitCode, 0) << r.err;
	EXPECT_NE(r.out.find("frames:       60"), std::string::npos) << r.out;
	EXPECT_NE(r.out.find("100 um (exact)"), std::string::npos) << r.out;
	// yesslam-oni copies the detections beside the recording (issue 30: a run on the .oni used to
	// switch detectors without them).
	EXPECT_NE(r.out.find("detections:   " + dir + "/detections.txt"), std::string::npos) << r.out;
	EXPECT_EQ(readText(dir + "/detections.txt"), readText(seq + "/detections.txt"));
	return oni;
}
}  // namespace yesslam_test
