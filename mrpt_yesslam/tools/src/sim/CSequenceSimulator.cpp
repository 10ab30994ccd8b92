#include "mrpt_yesslam/sim/CSequenceSimulator.h"

#include "SimModelHash.h"
#include "SimRunSteps.h"

#include <mrpt/img/CImage.h>
#include <mrpt/math/CMatrixDynamic.h>
#include <mrpt/opengl/COpenGLScene.h>

#include <algorithm>
#include <set>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "mrpt_yesslam/detection/CDetectionsFileDetector.h"
#include "mrpt_yesslam/sim/CSensorStatistics.h"
#include "mrpt_yesslam/geometry/CPinholeCamera.h"
#include "mrpt_yesslam/io/CRawlogWriter.h"
#include "mrpt_yesslam/io/RgbdCamera.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/io/SceneExport.h"
#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/geometry/RelativeMotion.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/sim/CSimWorld.h"
#include "mrpt_yesslam/sim/SimPresets.h"
#include "mrpt_yesslam/sim/SimSensorModel.h"
#include "mrpt_yesslam/sim/SimTextures.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/CAsyncPngWriter.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;
using mrpt::poses::CPose3D;

namespace mrpt_yesslam
{
std::string simulatorModelHash()
{
	return YESSLAM_SIM_MODEL_HASH;
}

using sim_detail::stampText;
using sim_detail::TStageClock;
using sim_detail::unoccludedPixels;

TSimSummary runSimulation(const TSimOptions& o, const std::function<void(std::size_t, std::size_t)>& progress,
						  const std::function<bool()>& cancel)
{
	const auto t0 = std::chrono::steady_clock::now();
	TSimSummary sum;
	TStageClock clock(sum.stageSeconds);
	const auto& presets = simPresets();
	const auto pit =
		std::find_if(presets.begin(), presets.end(), [&](const TSimPreset& p) { return p.name == o.preset; });
	if (pit == presets.end())
	{
		std::string names;
		for (const auto& p : presets) names += (names.empty() ? "" : ", ") + p.name;
		throw InputError("", "unknown preset '" + o.preset + "' (known: " + names + ")");
	}
	const TSimPreset& preset = *pit;
	const bool realSensor = o.realSensor || preset.realSensor;  // the crowd preset has it on
	if (o.detNoise != "none" && o.detNoise != "yolo")
		throw InputError("", "--det-noise must be none or yolo, got '" + o.detNoise + "'");
	if (o.outDir.empty()) throw InputError("", "no output folder given (--out)");
	if (!(o.speed >= 0.1 && o.speed <= 10)) throw InputError("", "--speed must be in 0.1..10");

	// Frame stamps and camera poses: the preset's motion at 30 Hz, or a replayed TUM trajectory.
	std::vector<double> stamps;
	std::vector<CPose3D> poses;
	const CPose3D base = basePose();
	const double epoch = 1341846313.0;
	if (!o.trajectoryFile.empty())
	{
		const TTrajectory traj = readTumTrajectory(o.trajectoryFile);
		if (traj.size() < 2) throw InputError(o.trajectoryFile, "trajectory needs at least 2 poses");
		const CPose3D g0inv = -traj.front().asPose();
		const std::size_t n = o.frames ? std::min(o.frames, traj.size()) : traj.size();
		for (std::size_t k = 0; k < n; k++)
		{
			stamps.push_back(traj[k].t);
			poses.push_back(base + (g0inv + traj[k].asPose()));
		}
	}
	else
	{
		const std::size_t n =
			o.frames ? o.frames : static_cast<std::size_t>(std::ceil(static_cast<double>(preset.frames) / o.speed));
		for (std::size_t k = 0; k < n; k++)
		{
			const double t = k / 30.0;
			stamps.push_back(epoch + t);
			poses.push_back(base + presetMotion(preset.motion, t * o.speed, o.seed));
		}
	}

	// Inputs first: a run that cannot start leaves no output folder behind.
	if (!(o.depthOffsetMs == -1 || (o.depthOffsetMs >= 0 && o.depthOffsetMs <= 100)))
		throw InputError("", "--depth-offset must be in [0, 100] ms (or -1: the preset's)");
	double depthOffsetMs = o.depthOffsetMs < 0 ? preset.depthOffsetMs : o.depthOffsetMs;
	// Every reader pairs a depth image with the colour image nearest its stamp (TUM's associate.py): one over half a
	// frame from its own would pair with the next. Half a frame is the most free-running streams are apart (the real
	// Bonn slice's are), so 0.05 ms beyond is let through; a preset's offset is held to it, one asked for refused.
	// The median interval between frames (seconds; 0 for a single frame): a frame, for the depth
	// offset here and the readout below.
	double medianInterval = 0;
	if (stamps.size() > 1)
	{
		std::vector<double> gaps;
		for (std::size_t k = 1; k < stamps.size(); k++) gaps.push_back(stamps[k] - stamps[k - 1]);
		std::nth_element(gaps.begin(), gaps.begin() + static_cast<long>(gaps.size() / 2), gaps.end());
		medianInterval = gaps[gaps.size() / 2];
	}
	if (depthOffsetMs > 0 && stamps.size() > 1)
	{
		const double halfFrameMs = 500 * medianInterval;
		if (!(halfFrameMs > 0))
			throw InputError(o.trajectoryFile,
							 "the frames' stamps do not increase (most repeat): a depth offset needs frame intervals; "
							 "use --depth-offset 0");
		if (depthOffsetMs > halfFrameMs + 0.05)  // the preset's 16.7 at 30 Hz is within
		{
			if (o.depthOffsetMs >= 0)
			{
				char msg[200];
				std::snprintf(msg, sizeof(msg),
							  "--depth-offset %.1f ms is more than half a frame (%.2f ms here): each depth image would "
							  "be paired with the next colour image",
							  depthOffsetMs, halfFrameMs);
				throw InputError(o.trajectoryFile, msg);
			}
			depthOffsetMs = halfFrameMs;
		}
	}
	if (!(o.readoutMs == -1 || (o.readoutMs >= 0 && o.readoutMs <= 100)))
		throw InputError("", "--readout must be in [0, 100] ms");
	const std::vector<cv::Mat> photos =
		o.texturesDir.empty() ? std::vector<cv::Mat>() : loadPhotoTextures(o.texturesDir, 512);
	std::error_code ec;
	fs::create_directories(fs::path(o.outDir), ec);
	if (ec || !fs::is_directory(o.outDir)) throw InputError(o.outDir, "cannot create output folder");
	for (const char* sub : {"rgb", "depth", "labels/class", "labels/instance", "sequence_Images"})
	{
		if (!o.writeRawlog && std::string(sub) == "sequence_Images")
			continue;  // the rawlog's images: no rawlog, no folder
		fs::create_directories(fs::path(o.outDir) / sub, ec);
		if (ec) throw InputError((fs::path(o.outDir) / sub).string(), "cannot create folder (" + ec.message() + ")");
	}
	const fs::path out(o.outDir);

	// The world and its people.
	CSimWorld world(o.roomSeed ? o.roomSeed : o.seed, photos, preset.bareWalls);
	// With a room seed, the pass's seed also moves the people along their paths (another start time),
	// so that a second pass through the same room meets them elsewhere. Without one, as before.
	const double phase = o.roomSeed ? 1.7 * static_cast<double>(o.seed % 11) : 0.0;
	std::mt19937 layout(o.seed * 2654435761u + 11);
	std::uniform_real_distribution<double> u(0, 1);
	const int walkers = preset.walking > 0 ? (o.people >= 0 ? o.people : preset.walking) : 0;
	const int sitters = preset.sitting > 0 ? (o.people >= 0 ? o.people : preset.sitting) : 0;
	using P2 = mrpt::math::TPoint2D;
	for (int k = 0; k < walkers; k++)
	{
		// The tour's camera circles the room centre: its people cross the far and near halves of
		// the room, in front of the walls the camera looks at, never through the camera.
		if (preset.motion == "pan" && k < 3)
		{
			// The crowd: one across the view about a metre in front of the camera (a person there is
			// 270 px wide and taller than the image: half the view), one the other way further out,
			// one walking up to the camera and away again.
			if (k == 0)
				world.addWalkingPerson({P2(3.0, 0.6), P2(3.05, 4.4)}, 0.9, 0.0 + phase);
			else if (k == 1)
				world.addWalkingPerson({P2(3.8, 4.3), P2(3.6, 0.7)}, 1.0, 2.5 + phase);
			else
				world.addWalkingPerson({P2(4.8, 1.6), P2(2.9, 2.35), P2(4.8, 3.4)}, 0.8, 5.0 + phase);
		}
		else if (preset.motion == "tour" && k < 2)
			world.addWalkingPerson(
				k == 0 ? std::vector<P2>{P2(4.1, 0.9), P2(4.3, 4.1)} : std::vector<P2>{P2(1.1, 4.0), P2(1.0, 1.0)}, 0.9,
				2.0 * k + phase);
		else if (k == 0)  // comes close to the camera: covers much of the image for a while
			world.addWalkingPerson({P2(4.4, 1.2), P2(2.95, 2.3), P2(4.4, 3.8)}, 0.8, 0.0 + phase);
		else if (k == 1)
			world.addWalkingPerson({P2(3.5, 0.7), P2(3.6, 4.3)}, 1.1, 1.0 + phase);
		else
		{
			const double x = 3.0 + 1.3 * u(layout);
			world.addWalkingPerson({P2(x, 0.6 + 0.4 * u(layout)), P2(x + 0.3 * (u(layout) - 0.5), 4.4)},
								   0.8 + 0.5 * u(layout), 6 * u(layout));
		}
	}
	const CPose3D seats[3] = {CPose3D(4.5, 1.6, 0, M_PI, 0, 0), CPose3D(4.5, 3.4, 0, M_PI * 0.92, 0, 0),
							  CPose3D(3.4, 3.95, 0, -M_PI / 2, 0, 0)};
	for (int k = 0; k < sitters; k++)
		world.addSittingPerson(seats[k % 3] + CPose3D(0.1 * (k / 3), 0, 0, 0, 0, 0), 2.0 * k);
	if (o.movingChair) world.addMovingChair({P2(3.0, 1.2), P2(3.2, 3.8)}, 0.35);
	TRgbdCamera cam = tumCameraByName("fr3");
	const CBoxRaycaster renderer;

	std::unique_ptr<CRawlogWriter> rawlog;
	if (o.writeRawlog) rawlog = std::make_unique<CRawlogWriter>((out / "sequence.rawlog").string());
	std::string rgbTxt = "# color images\n# file: yesslam-sim " + o.preset + "\n# timestamp filename\n";
	std::string depthTxt = "# depth maps\n# file: yesslam-sim " + o.preset + "\n# timestamp filename\n";
	std::string assoc, objectsTxt = "# timestamp instance_id class_id visible_pixels visible_fraction x y w h moving\n";
	std::vector<TDetectionRecord> dets;
	TTrajectory gt;
	std::vector<double> shares;
	cv::Mat scratch(cam.intrinsics.nrows, cam.intrinsics.ncols, CV_8U);
	const auto& objs = world.objects();
	if (!(o.missRate >= 0 && o.missRate <= 1)) throw InputError("", "--miss-rate must be in [0, 1]");
	std::set<int> undetected;  // the first undetectedPeople moving people never reach detections.txt
	for (const auto& ob : objs)
		if (undetected.size() < o.undetectedPeople && ob.classId == 0 && ob.moves) undetected.insert(ob.id);
	if (undetected.size() < o.undetectedPeople)
		throw InputError("", "--undetected-people " + std::to_string(o.undetectedPeople) + ": the scene has only " +
								 std::to_string(undetected.size()) + " moving people");

	// The camera's pose at any stamp inside the sequence: poses are given at the colour stamps.
	const auto poseAt = [&](double s)
	{
		const auto it = std::upper_bound(stamps.begin(), stamps.end(), s);
		if (it == stamps.begin()) return poses.front();
		if (it == stamps.end()) return poses.back();
		const std::size_t j = static_cast<std::size_t>(it - stamps.begin());
		return interpolatePose(poses[j - 1], poses[j], (s - stamps[j - 1]) / (stamps[j] - stamps[j - 1]));
	};

	// Rolling shutter: bands of rows, each rendered from the camera (and people) at the band's
	// middle row's moment. 16 bands of 30 rows: at 28 ms and a camera turning 20 deg/s the image
	// shears 5 px from top to bottom, so the steps between bands stay a third of a pixel.
	// A sensor reads its rows within a frame period: a replayed trajectory's 100 Hz stamps get a
	// shorter readout (the frame interval), as a faster camera has.
	double readout = (o.readoutMs < 0 ? (realSensor ? 28.0 : 0.0) : o.readoutMs) * 1e-3;
	if (stamps.size() > 1) readout = std::min(readout, medianInterval);
	// Within a frame the camera moves smoothly, but a replayed motion-capture trajectory is not smooth at its 100 Hz
	// samples: rows posed between them took the capture's noise for motion and sheared the image beyond any correction.
	// There the rows move from the frame's pose with the trajectory's velocity over +-50 ms.
	const auto rowPose = [&](double stamp, double dt)
	{
		if (o.trajectoryFile.empty()) return poseAt(stamp + dt);
		constexpr double h = 0.05;
		return poseAt(stamp) + scaleMotion(poseAt(stamp + h) - poseAt(stamp - h), dt / (2 * h));
	};
	const auto renderRolling = [&](double stamp, cv::Mat& bgr, cv::Mat& depth, cv::Mat& instance)
	{
		const int H = static_cast<int>(cam.intrinsics.nrows), bands = 16;
		bgr.create(H, static_cast<int>(cam.intrinsics.ncols), CV_8UC3);
		depth.create(bgr.size(), CV_32F);
		instance.create(bgr.size(), CV_16U);
		for (int b = 0; b < bands; b++)
		{
			const int r0 = b * H / bands, r1 = (b + 1) * H / bands;
			const double dt = ((r0 + r1 - 1) / 2.0 - H / 2.0) / H * readout;
			world.setTime(stamp + dt - stamps[0]);
			renderer.render(world.rayBoxes(), rowPose(stamp, dt), cam.intrinsics, bgr, depth, instance,
							cv::Range(r0, r1));
		}
	};

	CAsyncPngWriter pngs(2, 16);
	clock.lap("setup");
	for (std::size_t k = 0; k < stamps.size(); k++)
	{
		if (cancel && cancel())
		{
			sum.interrupted = true;
			break;
		}
		const double t = stamps[k] - stamps[0];
		world.setTime(t);
		cv::Mat rgb, z, inst;
		if (readout > 0)
			renderRolling(stamps[k], rgb, z, inst);
		else
			renderer.render(world.rayBoxes(), poses[k], cam.intrinsics, rgb, z, inst);
		// The depth camera's own moment (--depth-offset): the scene rendered again there, people
		// and camera moved on; its colour is what the depth camera saw (dark surfaces below).
		// A triangle wave rather than the streams' sawtooth: at the sawtooth's wrap the depth stamp
		// would step back past the previous frame's (the real association then skips a depth
		// image), which a TUM list cannot hold. Same range, same drift rate.
		const double ph = std::fmod(static_cast<double>(k) / 444.0 + 0.37 * o.seed, 1.0);
		const double depthOffset = depthOffsetMs * 1e-3 * (ph < 0.5 ? 4 * ph - 1 : 3 - 4 * ph);
		const double depthStamp = stamps[k] + depthOffset;
		cv::Mat depthSceneRgb = rgb;
		if (depthOffset != 0)
		{
			cv::Mat inst2;
			if (readout > 0)
				renderRolling(depthStamp, depthSceneRgb, z, inst2);
			else
			{
				world.setTime(t + depthOffset);
				renderer.render(world.rayBoxes(), poseAt(depthStamp), cam.intrinsics, depthSceneRgb, z, inst2);
			}
			world.setTime(t);
		}
		clock.lap("render");

		// Class labels, visible pixels and box of every instance, share of moving pixels.
		cv::Mat cls = cv::Mat::zeros(inst.size(), CV_16U);
		std::vector<std::size_t> visible(objs.size() + 1, 0);
		std::vector<int> x0(objs.size() + 1, inst.cols), y0(objs.size() + 1, inst.rows), x1(objs.size() + 1, -1),
			y1(objs.size() + 1, -1);
		std::size_t dynamicPx = 0;
		for (int r = 0; r < inst.rows; r++)
		{
			const uint16_t* pi = inst.ptr<uint16_t>(r);
			uint16_t* pc = cls.ptr<uint16_t>(r);
			for (int c = 0; c < inst.cols; c++)
			{
				const int idx = world.indexOfId(pi[c]);
				if (idx < 0) continue;
				const auto& ob = objs[static_cast<std::size_t>(idx)];
				if (ob.classId >= 0) pc[c] = static_cast<uint16_t>(ob.classId + 1);
				const std::size_t ui = pi[c];
				visible[ui]++;
				x0[ui] = std::min(x0[ui], c);
				x1[ui] = std::max(x1[ui], c);
				y0[ui] = std::min(y0[ui], r);
				y1[ui] = std::max(y1[ui], r);
				dynamicPx += ob.moves;
			}
		}
		std::vector<cv::Rect> bbox(objs.size() + 1);
		for (std::size_t i = 0; i < bbox.size(); i++)
			if (visible[i]) bbox[i] = cv::Rect(x0[i], y0[i], x1[i] - x0[i] + 1, y1[i] - y0[i] + 1);
		const double share = static_cast<double>(dynamicPx) / (inst.rows * inst.cols);
		shares.push_back(share);
		clock.lap("labels");

		// Sensor effects, each from a per-frame seed so that runs are byte-identical.
		std::mt19937 rng(o.seed * 1000003u + static_cast<uint32_t>(k));
		cv::Mat drop;
		if (o.noise && realSensor)
		{
			cv::Mat grey;
			cv::cvtColor(depthSceneRgb, grey, cv::COLOR_BGR2GRAY);
			drop = coherentUniform(z.size(), 8, rng);
			addRealSensorDepthError(z, grey, drop, rng);
		}
		// With the smooth field carrying part of the error, the per-pixel part is smaller.
		if (o.noise) addDepthNoise(z, rng, cam, realSensor ? 0.6e-3f : 1.425e-3f, drop, realSensor ? 3 : 1);
		cv::Mat depth16;
		z.convertTo(depth16, CV_16U, 5000.0);
		// A real RGB-D camera's colour image is soft (small lens, Bayer demosaicing, compression):
		// a quarter of the 32 x 32 cells of these renderings with a FAST corner lose it (0.83 ->
		// 0.50-0.55, the real frames 0.39-0.43).
		if (realSensor) cv::GaussianBlur(rgb, rgb, cv::Size(), 1.0);
		if (o.autoExposure || realSensor) rgb.convertTo(rgb, -1, 1.0 + 0.15 * std::sin(t * 2 * M_PI / 6.0), 0);
		if ((o.motionBlur || realSensor) && k > 0)
		{
			// Blur along the image motion of the centre pixel between frames.
			const auto pc = (-poses[k]).composePoint(poses[k - 1].composePoint(mrpt::math::TPoint3D(0, 0, 2)));
			const CPinholeCamera pin(cam.intrinsics);
			double u = 0, v = 0;
			pin.project(pc.x, pc.y, pc.z, u, v);
			const double dx = u - pin.cx(), dy = v - pin.cy();
			const int len = std::min(15, static_cast<int>(std::hypot(dx, dy)));
			if (len >= 2)
			{
				cv::Mat kernel = cv::Mat::zeros(len, len, CV_32F);
				cv::line(kernel, {0, 0},
						 {len - 1, static_cast<int>(std::abs(dy) / std::max(1e-9, std::hypot(dx, dy)) * (len - 1))},
						 1.0);
				kernel /= std::max(1.0, cv::sum(kernel)[0]);
				cv::filter2D(rgb, rgb, -1, kernel);
			}
		}

		// Sensor noise last: it arises at readout, after the optics and the exposure's motion blur (added before the
		// blur, it was smoothed). 1.3 a channel matches the real frames of ../shared (Immerkaer's estimate); their
		// Laplacian variance is edges, not noise (docs/benchmarks.md, "Simulator against real frames").
		if (o.noise)
		{
			cv::Mat n(rgb.size(), CV_16SC3);
			cv::theRNG().state = o.seed * 7777u + k;
			cv::randn(n, cv::Scalar::all(0), cv::Scalar::all(realSensor ? 1.3 : 2.5));
			cv::Mat r16;
			rgb.convertTo(r16, CV_16SC3);
			r16 += n;
			r16.convertTo(rgb, CV_8UC3);
		}
		clock.lap("sensor noise");

		// Objects: visible box, visible fraction, and simulated detections.
		std::uniform_real_distribution<double> uu(0, 1);
		std::normal_distribution<double> nn(0, 1);
		for (std::size_t i = 0; i < objs.size(); i++)
		{
			const auto& ob = objs[i];
			const std::size_t id = static_cast<std::size_t>(ob.id);
			if (ob.classId < 0 || visible[id] == 0) continue;
			const std::size_t full = unoccludedPixels(world, static_cast<int>(i), poses[k], cam, scratch);
			const double frac =
				full > 0 ? std::min(1.0, static_cast<double>(visible[id]) / static_cast<double>(full)) : 1.0;
			const cv::Rect b = bbox[id];
			char line[256];
			std::snprintf(line, sizeof(line), "%s %d %d %zu %.3f %d %d %d %d %d\n", stampText(stamps[k]).c_str(), ob.id,
						  ob.classId, visible[id], frac, b.x, b.y, b.width, b.height, ob.moves ? 1 : 0);
			objectsTxt += line;
			if (undetected.count(ob.id)) continue;
			// Drawn only when asked, so that sequences without it stay byte-identical.
			if (o.missRate > 0 && ob.moves && uu(rng) < o.missRate) continue;
			TDetectionRecord r;
			r.t = stamps[k];
			r.det.classId = ob.classId;
			r.det.instanceId = ob.id;
			if (o.detNoise == "none")
			{
				// Exact: every object with a visible pixel, the box of its visible pixels.
				r.det.score = 1.0f;
				r.det.box = cv::Rect2f(b);
			}
			else
			{
				// Like a real detector: small or mostly hidden objects are missed, boxes jitter by a
				// few percent of their size, scores spread over [0.6, 1).
				const double size = std::sqrt(static_cast<double>(b.area()));
				const double pDetect =
					0.97 * std::clamp((frac - 0.15) / 0.2, 0.0, 1.0) * std::clamp((size - 12) / 25, 0.0, 1.0);
				if (uu(rng) >= pDetect) continue;
				const double jx = 0.03 * b.width, jy = 0.03 * b.height;
				const double x0 = b.x + jx * nn(rng), y0 = b.y + jy * nn(rng);
				const double x1 = b.x + b.width + jx * nn(rng), y1 = b.y + b.height + jy * nn(rng);
				r.det.score =
					static_cast<float>(std::min(0.995, 0.6 + 0.4 * std::pow(uu(rng), 0.35) * (0.7 + 0.3 * frac)));
				r.det.box = cv::Rect2f(cv::Point2f(static_cast<float>(x0), static_cast<float>(y0)),
									   cv::Point2f(static_cast<float>(x1), static_cast<float>(y1))) &
							cv::Rect2f(0, 0, static_cast<float>(inst.cols), static_cast<float>(inst.rows));
				if (r.det.box.area() < 4) continue;
			}
			dets.push_back(r);
			sum.detections++;
		}
		if (o.detNoise == "yolo" && uu(rng) < 0.03)
		{
			// An occasional false positive, with the low score such boxes usually have.
			TDetectionRecord r;
			r.t = stamps[k];
			r.det.classId = uu(rng) < 0.5 ? 0 : 56;
			r.det.score = static_cast<float>(0.6 + 0.12 * uu(rng));
			r.det.box = cv::Rect2f(static_cast<float>(uu(rng) * 500), static_cast<float>(uu(rng) * 350),
								   static_cast<float>(40 + uu(rng) * 100), static_cast<float>(60 + uu(rng) * 100));
			r.det.instanceId = -1;
			dets.push_back(r);
			sum.detections++;
		}

		clock.lap("objects+detections");
		const std::string name = stampText(stamps[k]) + ".png";
		if (o.overlays)
		{
			// Colour image with each labelled object tinted by its instance and people outlined.
			cv::Mat ov = rgb.clone();
			for (int r = 0; r < ov.rows; r++)
				for (int c = 0; c < ov.cols; c++)
				{
					const int id = inst.at<uint16_t>(r, c);
					if (id == 0 || cls.at<uint16_t>(r, c) == 0) continue;
					const cv::Vec3b tint(static_cast<uchar>((id * 67) % 256), static_cast<uchar>((id * 131) % 256),
										 static_cast<uchar>((id * 29 + 128) % 256));
					ov.at<cv::Vec3b>(r, c) = ov.at<cv::Vec3b>(r, c) / 2 + tint / 2;
				}
			for (std::size_t i = 0; i < objs.size(); i++)
			{
				const std::size_t id = static_cast<std::size_t>(objs[i].id);
				if (objs[i].classId < 0 || visible[id] == 0) continue;
				const cv::Scalar col = objs[i].moves ? cv::Scalar(0, 0, 255) : cv::Scalar(0, 200, 0);
				cv::rectangle(ov, bbox[id], col, objs[i].moves ? 2 : 1);
				cv::putText(ov, objs[i].name, bbox[id].tl() + cv::Point(2, 12), cv::FONT_HERSHEY_SIMPLEX, 0.4, col, 1,
							cv::LINE_AA);
			}
			fs::create_directories(out / "labels/overlay", ec);
			pngs.write((out / "labels/overlay" / name).string(), ov);
		}
		// Colour images of the rawlog are external (MRPT's "<rawlog>_Images/" convention), hard links
		// to the PNGs in rgb/: no second copy on disk and no second encoding.
		std::function<void()> linkForRawlog;
		if (rawlog)
			linkForRawlog = [out, name]
			{
				std::error_code lec;
				const fs::path link = out / "sequence_Images" / name;
				fs::remove(link, lec);
				fs::create_hard_link(out / "rgb" / name, link, lec);
				if (lec) fs::copy_file(out / "rgb" / name, link, fs::copy_options::overwrite_existing, lec);
				if (lec) throw InputError(link.string(), "cannot write image (" + lec.message() + ")");
			};
		clock.lap("overlays");
		pngs.write((out / "rgb" / name).string(), rgb, linkForRawlog);
		const std::string depthName = stampText(depthStamp) + ".png";
		pngs.write((out / "depth" / depthName).string(), depth16);
		pngs.write((out / "labels/class" / name).string(), cls);
		pngs.write((out / "labels/instance" / name).string(), inst);
		rgbTxt += stampText(stamps[k]) + " rgb/" + name + "\n";
		depthTxt += stampText(depthStamp) + " depth/" + depthName + "\n";
		assoc += stampText(stamps[k]) + " rgb/" + name + " " + stampText(depthStamp) + " depth/" + depthName + "\n";
		gt.push_back(TStampedPose::fromPose(stamps[k], poses[k]));
		clock.lap("png queue wait");
		if (rawlog)
		{
			auto obs = makeRgbdObservation(stamps[k], rgb, depth16, cam, "RGBD_SIM");
			mrpt::img::CImage ext;
			ext.setExternalStorage(name);
			obs->intensityImage = ext;
			rawlog->write(*obs);
		}
		clock.lap("rawlog");
		sum.frames++;
		if (progress) progress(sum.frames, stamps.size());
	}

	pngs.finish();
	clock.lap("png queue wait");
	// The lists and files that make the folder a TUM sequence, then the rest.
	writeFileAtomically((out / "rgb.txt").string(), rgbTxt);
	writeFileAtomically((out / "depth.txt").string(), depthTxt);
	writeFileAtomically((out / "associations.txt").string(), assoc);
	writeTumTrajectory((out / "groundtruth.txt").string(), gt,
					   "ground truth trajectory\nfile: yesslam-sim " + o.preset + "\ntimestamp tx ty tz qx qy qz qw");
	writeFileAtomically((out / "calibration.txt").string(),
						"# TUM fr3 intrinsics (no distortion): fx fy cx cy width height depth_scale\n535.4 539.2 320.1 "
						"247.6 640 480 5000\n");
	writeDetectionsFile((out / "detections.txt").string(), dets);
	writeFileAtomically((out / "objects.txt").string(), objectsTxt);
	if (rawlog)
	{
		rawlog->commit();
		writeTumTrajectory((out / "sequence_groundtruth.txt").string(), gt, "ground truth of sequence.rawlog");
	}
	saveSceneAtomically(*world.scene(), (out / "scene.3Dscene").string());

	double mean = 0, mx = 0;
	for (double s : shares)
	{
		mean += s;
		mx = std::max(mx, s);
	}
	mean = shares.empty() ? 0 : mean / static_cast<double>(shares.size());
	sum.meanDynamicShare = mean;
	sum.maxDynamicShare = mx;
	std::string meta = "{\n  \"tool\": \"yesslam-sim\",\n";
	meta += "  \"command\": \"" + jsonEscape(o.commandLine) + "\",\n";
	meta += "  \"model\": \"" + simulatorModelHash() + "\",\n";
	meta += "  \"preset\": \"" + o.preset + "\",\n  \"seed\": " + std::to_string(o.seed) + ",\n";
	if (o.roomSeed) meta += "  \"room_seed\": " + std::to_string(o.roomSeed) + ",\n";
	meta += "  \"frames\": " + std::to_string(sum.frames) + ",\n  \"walking_people\": " + std::to_string(walkers) +
			",\n  \"sitting_people\": " + std::to_string(sitters) + ",\n";
	meta += std::string("  \"noise\": ") + (o.noise ? "true" : "false") +
			",\n  \"real_sensor\": " + (realSensor ? "true" : "false") + ",\n  \"det_noise\": \"" + o.detNoise +
			"\",\n";
	meta += "  \"speed\": " + std::to_string(o.speed) + ",\n  \"depth_offset_ms\": " + std::to_string(depthOffsetMs) +
			",\n";
	meta += "  \"readout_ms\": " + std::to_string(readout * 1e3) + ",\n";
	meta += "  \"undetected_people\": " + std::to_string(o.undetectedPeople) +
			",\n  \"miss_rate\": " + std::to_string(o.missRate) + ",\n";
	meta += "  \"trajectory\": \"" + jsonEscape(o.trajectoryFile) + "\",\n  \"textures\": \"" +
			jsonEscape(o.texturesDir) + "\",\n";
	meta +=
		"  \"camera\": {\"fx\": 535.4, \"fy\": 539.2, \"cx\": 320.1, \"cy\": 247.6, \"width\": 640, \"height\": 480, "
		"\"depth_scale\": 5000},\n";
	meta +=
		"  \"labels\": {\"class_png\": \"COCO class id + 1 (0 = room structure or nothing)\", \"instance_png\": "
		"\"instance id (objects.txt), 0 = nothing\"},\n";
	char b[64];
	std::snprintf(b, sizeof(b), "%.5f", mean);
	meta += std::string("  \"dynamic_share_mean\": ") + b + ",\n";
	std::snprintf(b, sizeof(b), "%.5f", mx);
	meta += std::string("  \"dynamic_share_max\": ") + b + ",\n  \"dynamic_share_per_frame\": [";
	for (std::size_t i = 0; i < shares.size(); i++)
	{
		std::snprintf(b, sizeof(b), "%s%.4f", i ? ", " : "", shares[i]);
		meta += b;
	}
	meta += "]\n}\n";
	writeFileAtomically((out / "meta.json").string(), meta);
	clock.lap("finish");
	clock.add("png encode (threads)", pngs.busySeconds());
	sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
	return sum;
}
}  // namespace mrpt_yesslam
