// The whole pipeline on a yesslam-sim walking sequence: accuracy against the exact ground truth,
// people kept out of the map, deterministic sequential mode, parallel mode, and the outputs.
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/serialization/CArchive.h>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <set>
#include <thread>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "TestUtils.h"
#include "mrpt_yesslam/eval/TrajectoryEvaluator.h"
#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"
#include "mrpt_yesslam/io/CRawlogSource.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/sim/CSequenceSimulator.h"
#include "mrpt_yesslam/jobs/SlamJob.h"
#include "mrpt_yesslam/mapio/MapFile.h"
#include "mrpt_yesslam/system/CMapCheckpointer.h"
#include "mrpt_yesslam/util/TextParsing.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
// One walking_xyz sequence for the whole suite (rendering it is the slow part; ctest runs every
// test in its own process, hence the cache).
const std::string& walkingSequence()
{
	static const std::string path = walkingSequence60();
	return path;
}

// The system itself on the walking sequence: sequential (deterministic) unless `parallel`, its
// detections.txt.
TYesSlamOptions walkingSystemOptions(bool parallel = false)
{
	TYesSlamOptions o;
	o.detector.backend = "file";
	o.detector.file = walkingSequence() + "/detections.txt";
	o.system.parallel = parallel;
	return o;
}

// The walking sequence's true class labels (COCO id + 1, 16-bit) of the frame at time t.
cv::Mat classLabelsAt(double t)
{
	char name[64];
	std::snprintf(name, sizeof(name), "/labels/class/%.6f.png", t);
	const cv::Mat cls = cv::imread(walkingSequence() + name, cv::IMREAD_UNCHANGED);
	EXPECT_FALSE(cls.empty()) << name;
	return cls;
}

TSlamJobOptions jobFor(const std::string& out, bool parallel)
{
	TSlamJobOptions o;
	o.input = walkingSequence();
	o.outDir = out;
	o.slam.detector.backend = "auto";  // the simulator's detections.txt, with yolo-like noise
	o.slam.system.parallel = parallel;
	return o;
}

double ateOf(const TSlamJobSummary& s)
{
	EXPECT_TRUE(s.evaluated) << s.evalProblem;
	return s.eval.ate.stats.rmse;
}

// ATE of a sequential run of `seq` with the geometric check's mover test on or off.
double ateWithMoverCheck(const std::string& seq, bool movers)
{
	TempDir d(movers ? "system_movers_on" : "system_movers_off");
	TSlamJobOptions o;
	o.input = seq;
	o.outDir = d.path();
	o.slam.detector.backend = "auto";
	o.slam.system.parallel = false;
	o.slam.geometric.movers = movers;
	return ateOf(runSlamJob(o));
}
}  // namespace

TEST(System, WalkingSequenceIsTrackedAccurately)
{
	TempDir d("system_walk");
	const auto s = runSlamJob(jobFor(d.path(), false));
	EXPECT_EQ(s.stats.frames, 60u);
	EXPECT_EQ(s.stats.trackedFrames, 60u);
	EXPECT_GE(s.stats.keyFrames, 3u);
	EXPECT_LT(ateOf(s), 0.02);
	EXPECT_NE(s.detector.find("detections.txt"), std::string::npos);

	// Every output exists and parses.
	EXPECT_EQ(readTumTrajectory(d / "trajectory.txt").size(), 60u);
	EXPECT_EQ(readTumTrajectory(d / "keyframes.txt").size(), s.stats.keyFrames - s.stats.culledKeyFrames);
	mrpt::opengl::COpenGLScene scene;
	mrpt::io::CFileGZInputStream f(d / "map.3Dscene");
	mrpt::serialization::archiveFrom(f) >> scene;
	EXPECT_GE(scene.getViewport()->size(), s.stats.keyFrames + 1);  // cloud + a frustum per keyframe (+ path)
	std::ifstream js(d / "stats.json");
	const std::string json((std::istreambuf_iterator<char>(js)), std::istreambuf_iterator<char>());
	for (const char* k : {"\"tracking_rate\": 1.0000", "\"keyframes\"", "\"track\": {\"median\"", "\"mapping\""})
		EXPECT_NE(json.find(k), std::string::npos) << k;
	EXPECT_TRUE(fs::exists(d / "config_used.ini"));
	EXPECT_TRUE(fs::exists(d / "eval.json"));
	// With ground truth, the ATE picture too (issue 30 item 9).
	const cv::Mat plot = cv::imread(d / "ate.png");
	EXPECT_EQ(plot.cols, 1000);
	EXPECT_EQ(plot.rows, 800);
}

TEST(System, DynamicFilterKeepsPeopleOutOfTheMap)
{
	// Keypoints of keyframes that carry map points, checked against the true class labels: with the
	// filter almost none lie on a person, without it many do.
	auto personShare = [](bool filter)
	{
		TYesSlamOptions o = walkingSystemOptions();
		o.system.dynamicFilter = filter;
		CYesSlamSystem sys(o);
		auto src = openInputSource(walkingSequence(), o.input);
		while (auto obs = src->next()) sys.processFrame(*obs);
		std::size_t onPerson = 0, all = 0;
		for (TKeyFrameId k : sys.map().keyFrameIds())
		{
			const CKeyFrame kf = sys.map().keyFrame(k);
			const cv::Mat cls = classLabelsAt(kf.timestamp);
			if (cls.empty()) continue;
			for (std::size_t i = 0; i < kf.mapPoints.size(); i++)
			{
				if (kf.mapPoints[i] < 0) continue;
				const auto& p = kf.features->keypoints[i].pt;
				all++;
				onPerson += cls.at<uint16_t>(cvRound(p.y), cvRound(p.x)) == 1;  // COCO person (0) + 1
			}
		}
		return all ? static_cast<double>(onPerson) / static_cast<double>(all) : 1.0;
	};
	const double filtered = personShare(true), unfiltered = personShare(false);
	// Measured: 1.3% with the filter (mask borders, missed detections), 4.1% without.
	EXPECT_LT(filtered, 0.02);
	EXPECT_GT(unfiltered, 2.5 * filtered);
}

TEST(System, WithoutTheDynamicFilterAPersonsKeypointsReachThePoseSolve)
{
	// --no-dynamic-filter is the baseline: no mask, no geometric check, no mover check, no
	// see-through culling. Keypoints on people (true class labels) must then be pose inliers, none
	// may be held back as uncertain, and tracking may erase no map point as moving.
	struct TCount
	{
		std::size_t personInliers = 0, inliers = 0, uncertain = 0, movingErased = 0;
	};
	auto run = [](bool filter)
	{
		TempDir d(filter ? "system_baseline_on" : "system_baseline_off");
		auto o = jobFor(d.path(), false);
		o.slam.detector.backend = "file";
		o.slam.detector.file = walkingSequence() + "/detections.txt";
		o.slam.system.dynamicFilter = filter;
		o.slam.dense.enabled = false;
		TCount c;
		o.onFrame = [&](const TFrame& f)
		{
			for (std::size_t i = 0; i < f.size(); i++) c.uncertain += f.features.isUncertain(i);
			if (!f.tracked) return;
			const cv::Mat cls = classLabelsAt(f.timestamp);
			if (cls.empty()) return;
			for (std::size_t i = 0; i < f.mapPoints.size(); i++)
			{
				if (f.mapPoints[i] < 0) continue;
				c.inliers++;
				// The raw keypoint position: the simulator's camera has no distortion.
				const auto& p = f.features.keypoints[i].pt;
				c.personInliers += cls.at<uint16_t>(cvRound(p.y), cvRound(p.x)) == 1;  // COCO person (0) + 1
			}
		};
		c.movingErased = runSlamJob(o).stats.movingPointsErased;
		return c;
	};
	const TCount off = run(false), on = run(true);
	EXPECT_EQ(off.uncertain, 0u) << "no keypoint may wait for a geometric check without the filter";
	EXPECT_EQ(off.movingErased, 0u) << "no map point may be erased as moving without the filter";
	// Measured: 1,806 person inliers of 17,487; with the mover check and see-through culling still
	// on, as before this test, 154 (and 2,090 uncertain keypoints, 212 map points erased as moving).
	EXPECT_GT(off.personInliers, 600u) << "of " << off.inliers << " inliers";
	// With the filter the people's keypoints stay out of the solve (measured: 1 person inlier; the
	// mask and the mover check do it: the box part that made keypoints uncertain is off while mapping).
	EXPECT_LT(static_cast<double>(on.personInliers), 0.2 * static_cast<double>(off.personInliers));
}

TEST(System, EveryPoseSaysWhereItComesFromAndTheOnlinePosesAreWhatTheRunHad)
{
	// Two blank frames before the sequence (no map can start from them: no pose at all), and five
	// blank frames in its middle (lost: coasted while the run went, filled in afterwards).
	TYesSlamOptions o = walkingSystemOptions();
	o.dense.enabled = false;
	CYesSlamSystem sys(o);
	auto src = openInputSource(walkingSequence(), o.input);
	std::size_t i = 0;
	std::vector<mrpt::poses::CPose3D> coasted;
	std::vector<TFrameReport> reports;
	sys.setFrameCallback(
		[&](const TFrame& f)
		{
			if (!f.tracked) coasted.push_back(f.pose);
		});
	while (auto obs = src->next())
	{
		const double t = mrpt::Clock::toDouble(obs->timestamp);
		const auto& K = obs->cameraParamsIntensity;
		const cv::Mat black = cv::Mat::zeros(static_cast<int>(K.nrows), static_cast<int>(K.ncols), CV_8UC3);
		const cv::Mat noDepth = cv::Mat::zeros(black.size(), CV_32F);
		if (i == 0)
			for (double dt : {0.2, 0.1}) reports.push_back(sys.processFrame(black, noDepth, t - dt, K));
		if (i >= 20 && i < 25)
			reports.push_back(sys.processFrame(black, noDepth, t, K));
		else
			reports.push_back(sys.processFrame(*obs));
		i++;
	}
	const auto rows = sys.frameLog();
	ASSERT_EQ(rows.size(), 62u);
	// What processFrame reported is what the online trajectory recorded, frame for frame (issue 63
	// item 1: a program on the library gets the pose trajectory_online.txt holds).
	ASSERT_EQ(reports.size(), 62u);
	{
		const TTrajectory on = sys.onlineTrajectory();
		std::size_t k = 0;
		for (const auto& r : reports)
		{
			if (!r.pose) continue;
			ASSERT_LT(k, on.size());
			EXPECT_LT((r.pose->asVectorVal() - on[k].asPose().asVectorVal()).norm(), 1e-9) << "frame " << r.frameId;
			k++;
		}
		EXPECT_EQ(k, on.size());
		EXPECT_FALSE(reports[0].pose.has_value()) << "no map yet: no pose";
	}
	for (std::size_t k = 0; k < rows.size(); k++)
	{
		const EPoseSource want = k < 2                 ? EPoseSource::None
								 : (k >= 22 && k < 27) ? EPoseSource::Interpolated
													   : EPoseSource::Tracked;
		EXPECT_EQ(poseSourceName(rows[k].pose), std::string(poseSourceName(want))) << "frame " << k;
	}
	// Frames without a pose are left out of every trajectory.
	const TTrajectory smoothed = sys.smoothedTrajectory(), online = sys.onlineTrajectory(), carried = sys.trajectory();
	ASSERT_EQ(carried.size(), 60u);
	ASSERT_EQ(smoothed.size(), 60u);
	ASSERT_EQ(online.size(), 60u);
	EXPECT_EQ(smoothed.front().t, rows[2].timestamp);
	// The online poses of the lost frames are the ones the run had then (the coasted guesses, seven
	// of them: the two blank frames before the map and the five lost ones); the smoothed file has
	// other poses there.
	ASSERT_EQ(coasted.size(), 7u);
	double moved = 0;
	for (std::size_t k = 0; k < 5; k++)
	{
		const auto on = online[20 + k].asPose(), sm = smoothed[20 + k].asPose();
		EXPECT_LT((on.asVectorVal() - coasted[2 + k].asVectorVal()).norm(), 1e-6) << "lost frame " << k;
		moved += (on.asVectorVal().head<3>() - sm.asVectorVal().head<3>()).norm();
	}
	EXPECT_GT(moved, 1e-4) << "the smoothed poses of the lost frames are filled in after the fact";
	// trajectory.txt keeps them where the run coasted them (carried by their keyframe, which
	// mapping may have moved since: within a few mm of the online pose, not filled in).
	double carriedOff = 0;
	for (std::size_t k = 0; k < 5; k++)
	{
		EXPECT_LT(
			(carried[20 + k].asPose().asVectorVal().head<3>() - online[20 + k].asPose().asVectorVal().head<3>()).norm(),
			0.01)
			<< "lost frame " << k;
		carriedOff +=
			(carried[20 + k].asPose().asVectorVal().head<3>() - smoothed[20 + k].asPose().asVectorVal().head<3>())
				.norm();
	}
	EXPECT_GT(carriedOff, 0.5 * moved) << "trajectory() does not fill the lost frames in";

	// Without lostInterpolate they stay coasted in both.
	o.output.lostInterpolate = false;
	CYesSlamSystem plain(o);
	auto src2 = openInputSource(walkingSequence(), o.input);
	i = 0;
	while (auto obs = src2->next())
	{
		const auto& K = obs->cameraParamsIntensity;
		if (i >= 20 && i < 25)
			plain.processFrame(cv::Mat::zeros(static_cast<int>(K.nrows), static_cast<int>(K.ncols), CV_8UC3),
							   cv::Mat::zeros(static_cast<int>(K.nrows), static_cast<int>(K.ncols), CV_32F),
							   mrpt::Clock::toDouble(obs->timestamp), K);
		else
			plain.processFrame(*obs);
		i++;
	}
	const auto rows2 = plain.frameLog();
	ASSERT_EQ(rows2.size(), 60u);
	for (std::size_t k = 20; k < 25; k++)
		EXPECT_EQ(poseSourceName(rows2[k].pose), std::string("coasted")) << "frame " << k;
}

TEST(System, SequentialModeIsDeterministic)
{
	TempDir a("system_det_a"), b("system_det_b");
	runSlamJob(jobFor(a.path(), false));
	runSlamJob(jobFor(b.path(), false));
	const auto ta = readTumTrajectory(a / "trajectory.txt"), tb = readTumTrajectory(b / "trajectory.txt");
	ASSERT_EQ(ta.size(), tb.size());
	for (std::size_t i = 0; i < ta.size(); i++)
	{
		EXPECT_EQ(ta[i].tx, tb[i].tx);
		EXPECT_EQ(ta[i].qw, tb[i].qw);
	}
}

TEST(System, ParallelMappingIsAsAccurate)
{
	TempDir d("system_par");
	const auto s = runSlamJob(jobFor(d.path(), true));
	EXPECT_EQ(s.stats.trackedFrames, 60u);
	EXPECT_LT(ateOf(s), 0.02);
}

TEST(System, KeyFramePoliciesBothWork)
{
	TempDir a("system_sem"), b("system_orb");
	auto oa = jobFor(a.path(), false), ob = jobFor(b.path(), false);
	ob.slam.keyFrames.policy = "orbslam";
	const auto sa = runSlamJob(oa), sb = runSlamJob(ob);
	EXPECT_LT(ateOf(sb), 0.02);
	// The paper's claim (figure 11): semantic selection needs fewer keyframes.
	EXPECT_LT(sa.stats.keyFrames, sb.stats.keyFrames);
	oa.slam.keyFrames.policy = "bogus";
	expectInputError([&] { runSlamJob(oa); }, {"policy", "bogus"});
}

TEST(System, MaxFramesAndMissingInputs)
{
	TempDir d("system_max");
	auto o = jobFor(d.path(), false);
	o.maxFrames = 7;
	EXPECT_EQ(runSlamJob(o).stats.frames, 7u);
	EXPECT_EQ(readTumTrajectory(d / "trajectory.txt").size(), 7u);
	o.input = d / "nothing_here";
	expectInputError([&] { runSlamJob(o); }, {"nothing_here"});
	o.input = walkingSequence();
	o.slam.detector.backend = "yolo";
	o.slam.detector.model = d / "no_such_model.cfg";
	expectInputError([&] { runSlamJob(o); }, {"no_such_model.cfg"});
}

// A sequence whose depth is zero everywhere (a sensor that gives no depth): the run ends normally
// with nothing tracked and says so, never a crash.
TEST(System, SequenceWithoutAnyDepth)
{
	TempDir d("nodepth");
	auto frames = makeSyntheticFrames(12, 640, 480);
	for (auto& f : frames) f.depth.setTo(0);
	writeTumFolder(d / "seq", frames);
	TSlamJobOptions o;
	o.input = d / "seq";
	o.outDir = d / "run";
	o.slam.detector.backend = "none";
	o.slam.system.parallel = false;
	// No map can start: an error that says why (issue 43; it was an exit 0 over empty outputs),
	// after the outputs that say what happened (stats.json: 12 frames, none tracked).
	expectInputError([&] { runSlamJob(o); }, {"no map was made", "none of the 12 frames", "no frame has any depth"});
	const std::string stats = readText(d / "run/stats.json");
	EXPECT_NE(stats.find("\"frames\": 12,"), std::string::npos) << stats;
	EXPECT_NE(stats.find("\"tracked_frames\": 0,"), std::string::npos) << stats;
	EXPECT_TRUE(fs::exists(d / "run/trajectory.txt"));
}

// Review findings on the system's threads and keyframe bookkeeping, each failing before its fix.
TEST(System, FrameBufferShorterThanTheIntervalIsRefused)
{
	TYesSlamOptions o;
	o.detector.backend = "none";
	o.keyFrames.semantic.interval = 10;
	o.system.frameBuffer = 8;  // Algorithm 1 could name a frame that has already left the buffer
	expectInputError([&] { CYesSlamSystem sys(o); }, {"frameBuffer", "interval"});
	o.system.frameBuffer = 10;
	EXPECT_NO_THROW(CYesSlamSystem sys(o));
}

// Issue 40 d: after a failure on the mapping stage, the error reached the caller while later
// keyframes were still being mapped, so the outputs written then came from a map still changing.
// Every keyframe's consumer takes its time and the second one fails: the keyframes after it are
// queued or mapped while it fails; when the error reaches the caller, no stage is still working.
TEST(System, AFailedStageSettlesEveryStageBeforeTheErrorReachesTheCaller)
{
	const TYesSlamOptions o = walkingSystemOptions(true);
	CYesSlamSystem sys(o);
	std::atomic<int> entered{0}, left{0};
	sys.setKeyFrameCallback(
		[&](TKeyFrameId k)
		{
			entered++;
			struct TLeave
			{
				std::atomic<int>& n;
				~TLeave() { n++; }
			} leave{left};
			std::this_thread::sleep_for(std::chrono::milliseconds(300));
			if (k == 1) throw std::runtime_error("disk full");
		});
	auto src = openInputSource(walkingSequence(), o.input);
	std::size_t errors = 0;
	while (auto obs = src->next())
	{
		try
		{
			sys.processFrame(*obs);
		}
		catch (const std::runtime_error&)
		{
			errors++;
			EXPECT_EQ(entered.load(), left.load()) << "a stage still ran when the error came";
		}
	}
	try
	{
		sys.waitForMapping();
	}
	catch (const std::runtime_error&)
	{
		errors++;
	}
	EXPECT_EQ(entered.load(), left.load()) << "a stage still ran when the error came";
	EXPECT_GE(errors, 1u);
	EXPECT_GE(entered.load(), 4);
}

// The same for the loop stage's own queue: when a keyframe's loop task fails, the tasks queued
// behind it still run on the stage; the error must not reach the caller (who then writes the
// outputs) before they are done. Before, collecting all of them dropped those after the failed one
// from the queue that settling waits on (issue 40 d, found by a review).
TEST(System, AFailedLoopTaskLeavesNoLaterOneRunningWhenTheErrorComes)
{
	const TYesSlamOptions o = walkingSystemOptions(true);
	ASSERT_TRUE(o.loop.detection.enabled);
	CYesSlamSystem sys(o);
	std::atomic<int> entered{0}, left{0};
	std::atomic<bool> release{false};
	sys.setLoopTaskHook(
		[&](TKeyFrameId)
		{
			const int n = ++entered;
			struct TLeave
			{
				std::atomic<int>& n;
				~TLeave() { n++; }
			} leave{left};
			if (n == 1)
			{
				// The first task holds the stage until the run is over, then fails: every later
				// keyframe's task is queued behind it by then.
				while (!release)
					std::this_thread::sleep_for(std::chrono::milliseconds(10));  // ctest's timeout bounds it
				throw std::runtime_error("disk full");
			}
			std::this_thread::sleep_for(std::chrono::milliseconds(100));
		});
	auto src = openInputSource(walkingSequence(), o.input);
	while (auto obs = src->next())
		ASSERT_NO_THROW(sys.processFrame(*obs)) << "the failing task is held until the run is over";
	release = true;
	EXPECT_THROW(sys.waitForMapping(), std::runtime_error);
	EXPECT_EQ(entered.load(), left.load()) << "a loop task still ran when the error came";
	EXPECT_GE(entered.load(), 3) << "the test needs tasks queued behind the failing one";
}

// Issue 40 (review): in sequential mode a keyframe is mapped inside the frame that made it, and a
// failure there ended processFrame before the frame was recorded: the run's outputs lacked the
// frame whose pose tracking had just given (in parallel mode the failure comes with a later frame,
// after this one was recorded). The third keyframe's mapping fails here; the frame that made it
// is in the frame log and the trajectory, and the error still reaches the caller.
TEST(System, AFrameWhoseInlineMappingFailsIsStillRecorded)
{
	const TYesSlamOptions o = walkingSystemOptions();
	ASSERT_FALSE(o.system.parallel);
	CYesSlamSystem sys(o);
	std::size_t keyFrames = 0;
	sys.setKeyFrameCallback(
		[&](TKeyFrameId)
		{
			if (++keyFrames == 3) throw std::runtime_error("disk full");
		});
	auto src = openInputSource(walkingSequence(), o.input);
	std::size_t given = 0;
	bool failed = false;
	while (auto obs = src->next())
	{
		given++;
		try
		{
			sys.processFrame(*obs);
		}
		catch (const std::runtime_error& e)
		{
			EXPECT_NE(std::string(e.what()).find("disk full"), std::string::npos) << e.what();
			failed = true;
			break;
		}
	}
	ASSERT_TRUE(failed) << "the test needs the mapping to fail";
	const auto log = sys.frameLog();
	ASSERT_EQ(log.size(), given) << "the frame whose mapping failed is missing";
	EXPECT_TRUE(log.back().tracked);
	EXPECT_EQ(sys.stats().frames, given);
	EXPECT_EQ(sys.trajectory().size(), given);
}

// Issue 40 (review): the keyframe and loop callbacks run on the mapping and loop stages; setting
// one while those run wrote the std::function another thread was reading (ThreadSanitizer: a data
// race; a torn function object can crash). A viewer attaches and detaches while a run goes on, so
// the setters swap the callback atomically and a call runs the one set when it started. Another
// thread replaces the keyframe and frame callbacks here, as fast as it can, while the mapping stage
// and the frame thread call them (the loop callback too, though this sequence closes no loop);
// the TSan suite runs it. Every keyframe's mapping and every frame calls exactly one of them.
TEST(System, CallbacksMayBeReplacedWhileTheStagesRun)
{
	const TYesSlamOptions o = walkingSystemOptions(true);
	CYesSlamSystem sys(o);
	std::atomic<bool> done{false}, attached{false};
	std::atomic<std::size_t> keyFrameCalls{0}, frameCalls{0};
	std::thread viewer(
		[&]
		{
			while (!done)
			{
				auto seen = std::make_shared<std::atomic<std::size_t>>(0);  // owned by the callbacks (CCallbackSlot)
				sys.setKeyFrameCallback(
					[&keyFrameCalls, seen](TKeyFrameId)
					{
						(*seen)++;
						keyFrameCalls++;
					});
				sys.setFrameCallback([&frameCalls](const TFrame&) { frameCalls++; });
				sys.setLoopCallback([seen](const TLoop&) { (*seen)++; });
				attached = true;
				std::this_thread::yield();
			}
		});
	struct TJoin  // however the test ends
	{
		std::atomic<bool>& done;
		std::thread& t;
		~TJoin()
		{
			done = true;
			if (t.joinable()) t.join();
		}
	} join{done, viewer};
	while (!attached) std::this_thread::yield();
	auto src = openInputSource(walkingSequence(), o.input);
	std::size_t frames = 0;
	while (auto obs = src->next())
	{
		sys.processFrame(*obs);
		frames++;
	}
	sys.waitForMapping();
	done = true;
	viewer.join();
	EXPECT_GT(sys.stats().keyFrames, 1u);
	EXPECT_GT(keyFrameCalls.load(), 0u);
	EXPECT_LE(keyFrameCalls.load(), sys.stats().keyFrames) << "a keyframe's mapping calls one callback once";
	EXPECT_EQ(frameCalls.load(), frames) << "every frame called the frame callback set then";
}

// A keyframe waiting in the mapping queue is already in the map, covisible with the ones being
// mapped: culling around them must not erase it before its own local mapping (its words, its new
// points, its loop detection) is done. Here each keyframe's mapping ends slowly, with everything
// culling may take around it culled (thresholds at zero): the keyframes queued meanwhile survive
// until they are mapped themselves. Before, a queued keyframe was erased under it.
TEST(System, AKeyFrameWaitingForItsMappingIsNeverCulled)
{
	const TYesSlamOptions o = walkingSystemOptions(true);
	CYesSlamSystem sys(o);
	std::size_t mapped = 0, culled = 0;
	std::vector<TKeyFrameId> erasedBeforeMapped;
	sys.setKeyFrameCallback(
		[&](TKeyFrameId k)
		{
			mapped++;
			if (sys.map().keyFrame(k).bad) erasedBeforeMapped.push_back(k);
			std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the next keyframes queue up
			culled += sys.mutableMap().cullRedundantKeyFrames(k, 0.0, 1, 10.0).size();
		});
	auto src = openInputSource(walkingSequence(), o.input);
	while (auto obs = src->next()) sys.processFrame(*obs);
	sys.waitForMapping();
	EXPECT_GE(mapped, 4u);
	EXPECT_GT(culled, 0u) << "the cull erased nothing: it proves nothing";
	EXPECT_TRUE(erasedBeforeMapped.empty())
		<< erasedBeforeMapped.size() << " keyframes were culled while they waited for their mapping";
}

TEST(System, MapCheckpointsWhileTheParallelStagesRunLeaveWholeMaps)
{
	// Issue 68 item 2: checkpoints read the map, the dense store and the world frame on a thread of
	// their own while tracking, local mapping and the dense stage change them (the TSan suite runs
	// this). Every checkpoint that was due is a whole map with its octree, and the run's world frame
	// is still found at the end, not fixed by a checkpoint.
	const TYesSlamOptions o = walkingSystemOptions(true);
	CYesSlamSystem sys(o);
	TempDir d("checkpoints");
	const std::string path = d / "map.ysm";
	CMapCheckpointer checkpoints(sys, path, 0.02);
	auto src = openInputSource(walkingSequence(), o.input);
	std::size_t frames = 0;
	while (auto obs = src->next())
	{
		sys.processFrame(*obs);
		checkpoints.tick();
		frames++;
		std::this_thread::sleep_for(std::chrono::milliseconds(10));  // a camera's pace, roughly
	}
	checkpoints.stop();
	sys.waitForMapping();
	const auto st = checkpoints.stats();
	EXPECT_GE(st.saved, 2u);
	EXPECT_EQ(st.failed, 0u) << st.lastError;
	EXPECT_GE(st.octrees, 1u);
	checkpoints.tick();  // stopped: nothing more
	EXPECT_EQ(checkpoints.stats().saved, st.saved);

	CSparseMap saved;
	std::unique_ptr<CSemanticOcTree> octree;
	ASSERT_NO_THROW(loadMapFile(path, saved, 0, &octree));
	EXPECT_GE(saved.numKeyFrames(), 1u);
	EXPECT_LE(saved.numKeyFrames(), sys.stats().keyFrames);
	ASSERT_TRUE(octree);
	EXPECT_GT(octree->size(), 0u);
	EXPECT_EQ(sys.trajectory().size(), frames);
}

TEST(System, ParallelMappingMapsEveryKeyFrameAndReportsItsFailures)
{
	const TYesSlamOptions o = walkingSystemOptions(true);
	CYesSlamSystem sys(o);
	std::atomic<std::size_t> mapped{0};
	// A consumer that takes its time: keyframes queue up behind it, none may be skipped.
	sys.setKeyFrameCallback(
		[&](TKeyFrameId)
		{
			std::this_thread::sleep_for(std::chrono::milliseconds(40));
			mapped++;
		});
	auto src = openInputSource(walkingSequence(), o.input);
	// trajectory() from another thread while frames are processed (a data race before: TSan).
	std::atomic<bool> running{true};
	std::thread reader(
		[&]
		{
			while (running) (void)sys.trajectory();
		});
	while (auto obs = src->next()) sys.processFrame(*obs);
	sys.waitForMapping();
	running = false;
	reader.join();
	const TSlamStats st = sys.stats();
	EXPECT_GE(st.keyFrames, 5u);
	EXPECT_EQ(mapped.load(), st.keyFrames);
	EXPECT_EQ(st.stageMs.at("mapping").size(), st.keyFrames);
	EXPECT_EQ(sys.trajectory().size(), 60u);
	// Each timed stage also has its thread's CPU time, which can never exceed the wall time it
	// was measured over (one thread: it runs at most all the time it is timed).
	for (const char* stage : {"orb", "track", "mapping"})
	{
		const auto& wall = st.stageMs.at(stage);
		const auto& cpu = st.stageMs.at(std::string(stage) + "_cpu");
		ASSERT_EQ(cpu.size(), wall.size()) << stage;
		// Two clocks: a small relative tolerance for their rates, an absolute one for their reading.
		for (std::size_t i = 0; i < wall.size(); i++) EXPECT_LE(cpu[i], wall[i] * 1.002 + 0.1) << stage << " " << i;
	}

	// A failure on the mapping thread reaches the caller as an error, not std::terminate.
	CYesSlamSystem failing(o);
	failing.setKeyFrameCallback(
		[](TKeyFrameId k)
		{
			if (k == 2) throw std::runtime_error("disk full");
		});
	auto src2 = openInputSource(walkingSequence(), o.input);
	bool reported = false;
	try
	{
		while (auto obs = src2->next()) failing.processFrame(*obs);
		failing.waitForMapping();
	}
	catch (const std::runtime_error& e)
	{
		reported = true;
		EXPECT_NE(std::string(e.what()).find("local mapping failed: disk full"), std::string::npos) << e.what();
	}
	EXPECT_TRUE(reported);
}

TEST(System, SequentialAndParallelMappingBuildTheSameKeyFrames)
{
	// Every keyframe is mapped in both modes (the parallel one used to map only the newest queued
	// keyframe): the same keyframes are inserted and the accuracy is the same.
	TempDir a("system_seq"), b("system_par2");
	const auto sa = runSlamJob(jobFor(a.path(), false)), sb = runSlamJob(jobFor(b.path(), true));
	EXPECT_EQ(sa.stats.stageMs.at("mapping").size(), sa.stats.keyFrames);
	EXPECT_EQ(sb.stats.stageMs.at("mapping").size(), sb.stats.keyFrames);
	EXPECT_NEAR(static_cast<double>(sb.stats.keyFrames), static_cast<double>(sa.stats.keyFrames), 2.0);
	EXPECT_LT(std::abs(ateOf(sa) - ateOf(sb)), 0.005);
}

TEST(System, AnUndetectedWalkerCannotDragTheCamera)
{
	// walking_xyz with one of its walkers never in detections.txt: neither the mask nor the box
	// check can help, only the geometric mover check. Measured (seeds 1-4): 6-20 mm with it,
	// 107-154 mm without; seed 1: 10 mm and 147 mm.
	TSimOptions sim;
	sim.preset = "walking_xyz";
	sim.frames = 60;
	sim.undetectedPeople = 1;
	const std::string seq = cachedSequence("system_undetected_60", sim);
	const double with = ateWithMoverCheck(seq, true), without = ateWithMoverCheck(seq, false);
	EXPECT_LT(with, 0.03);
	EXPECT_GT(without, 0.08) << "the undetected walker should drag the camera without the check";
}

TEST(System, TheBoxPartOfTheGeometricCheckIsOnWhereTheMapIsReadOnly)
{
	// [GeometricCheck] boxes = auto: on for localisation in a loaded map, off when mapping; an
	// explicit value stays (config_used.ini keeps "auto" and says in a comment which a run used).
	TYesSlamOptions o;
	ASSERT_EQ(o.geometric.boxes, "auto");
	EXPECT_EQ(o.effective().geometric.boxes, "false");
	o.system.localizeOnly = true;
	EXPECT_EQ(o.effective().geometric.boxes, "true");
	o.geometric.boxes = "false";
	EXPECT_EQ(o.effective().geometric.boxes, "false");
	o.system.localizeOnly = false;
	o.geometric.boxes = "true";
	EXPECT_EQ(o.effective().geometric.boxes, "true");
	// config_used.ini: "auto" stays auto with the choice said (a mapping run's file re-run with
	// --localize-only chooses again); an explicit value and the baseline's forced false stay plain.
	const auto used = [](const TYesSlamOptions& opts) { return CYesSlamSystem(opts).configUsed(); };
	TYesSlamOptions m = walkingSystemOptions();
	const std::string mapping = used(m);
	EXPECT_NE(mapping.find("\nboxes = auto\n"), std::string::npos);
	EXPECT_NE(mapping.find("boxes = auto chose false in this run"), std::string::npos);
	m.geometric.boxes = "true";
	EXPECT_NE(used(m).find("\nboxes = true\n"), std::string::npos);
	m.geometric.boxes = "auto";
	m.system.dynamicFilter = false;
	const std::string baseline = used(m);
	EXPECT_NE(baseline.find("\nboxes = false\n"), std::string::npos);
	EXPECT_EQ(baseline.find("boxes = auto chose"), std::string::npos);
}

TEST(System, AStaticSequenceIsNotMadeWorseByTheMoverCheck)
{
	TSimOptions sim;
	sim.preset = "static_office";
	sim.frames = 60;
	const std::string seq = cachedSequence("system_static_60", sim);
	const double with = ateWithMoverCheck(seq, true), without = ateWithMoverCheck(seq, false);
	EXPECT_LT(with, without * 1.15 + 0.001);
}

TEST(System, TheFrameCallbackSeesEveryFrameAsTrackingLeftIt)
{
	TempDir d("system_frame_cb");
	auto o = jobFor(d.path(), false);
	o.maxFrames = 12;
	std::size_t calls = 0, withInliers = 0;
	double lastStamp = 0;
	o.onFrame = [&](const TFrame& f)
	{
		calls++;
		EXPECT_GT(f.timestamp, lastStamp);
		lastStamp = f.timestamp;
		std::size_t n = 0;
		for (TPointId id : f.mapPoints) n += id >= 0;
		if (f.tracked && n == f.numInliers && n > 0) withInliers++;
	};
	const auto s = runSlamJob(o);
	EXPECT_EQ(calls, 12u);
	EXPECT_GE(withInliers, 10u) << "tracked frames carry their inliers' map points";
	EXPECT_EQ(s.stats.frames, 12u);
}

// Issue 41 item 5: with a dense map every frame keeps its colour and depth images, and the frames
// Algorithm 1 may still choose from ([System] frameBuffer) hold them until they leave the buffer.
// Once the run is over (before the outputs, the run's peak of memory) they are let go: only the
// tracker's last frame keeps its images.
TEST(System, TheRecentFramesImagesAreLetGoOnceTheRunIsOver)
{
	TYesSlamOptions o = walkingSystemOptions();
	ASSERT_TRUE(o.dense.enabled) << "the images are kept for the dense map";
	CYesSlamSystem sys(o);
	std::vector<std::weak_ptr<const TFrameImages>> images;
	sys.setFrameCallback([&](const TFrame& f) { images.push_back(f.images); });
	auto src = openInputSource(walkingSequence(), o.input);
	for (int i = 0; i < 20; i++)
		if (auto obs = src->next()) sys.processFrame(*obs);
	sys.waitForMapping();
	ASSERT_EQ(images.size(), 20u);
	const auto alive = [&]
	{
		std::size_t n = 0;
		for (const auto& w : images) n += !w.expired();
		return n;
	};
	EXPECT_GE(alive(), o.system.frameBuffer) << "the buffer holds its frames' images";
	sys.releaseRecentFrames();
	EXPECT_LE(alive(), 1u) << "only the last frame's";
	// The system goes on after it: the next frames are tracked and can still become keyframes.
	std::size_t tracked = 0;
	for (int i = 0; i < 10; i++)
		if (auto obs = src->next()) tracked += sys.processFrame(*obs).tracked;
	EXPECT_EQ(tracked, 10u);
}

TEST(System, ProgressTotalsAreTheFramesThisRunWillProcess)
{
	// Issue 30 item 8: the progress line's total was the input's length whatever --max-frames and
	// --skip-frames said (a 7-frame run of 60 frames stopped at 12 %).
	auto totals = [](std::size_t maxFrames, std::size_t skipFrames)
	{
		TempDir d("system_progress");
		auto o = jobFor(d.path(), false);
		o.maxFrames = maxFrames;
		o.skipFrames = skipFrames;
		o.slam.dense.enabled = false;
		std::set<std::size_t> seen;
		std::size_t last = 0;
		runSlamJob(o,
				   [&](std::size_t done, std::size_t total, const std::string&) { seen.insert(total), last = done; });
		EXPECT_EQ(seen.size(), 1u);
		EXPECT_EQ(last, seen.empty() ? 0 : *seen.begin()) << "the last frame reports done == total";
		return seen.empty() ? 0 : *seen.begin();
	};
	EXPECT_EQ(totals(7, 0), 7u);
	EXPECT_EQ(totals(0, 55), 5u);
	EXPECT_EQ(totals(3, 55), 3u);
}

TEST(System, ParallelLiveInputDropsWhatSlamCannotTakeAndRecordsEverything)
{
	// The live path in-process (capture thread, recorder thread, mapping and dense stages beside
	// tracking; the ThreadSanitizer suite runs this): the sequence played at 10x its recorded
	// speed, so frames are dropped; every captured frame reaches the recording.
	TempDir d("system_live");
	TSlamJobOptions o = jobFor(d / "run", true);
	o.live.realtime = true;
	o.live.speed = 10;
	o.record = d / "captured.rawlog";
	const TSlamJobSummary s = runSlamJob(o);
	EXPECT_TRUE(s.input.live);
	EXPECT_EQ(s.input.stats.captured, 60u);
	EXPECT_GT(s.input.stats.dropped, 0u);
	EXPECT_EQ(s.stats.frames + s.input.stats.dropped, s.input.stats.captured);
	EXPECT_EQ(s.input.recorded, 60u);
	CRawlogSource rec(o.record);
	std::size_t n = 0;
	while (rec.next()) n++;
	EXPECT_EQ(n, 60u);
	EXPECT_GT(s.stats.trackedFrames, s.stats.frames / 2);
}

TEST(System, AMappingFailureStillCommitsTheRecordingOfTheFramesSoFar)
{
	// Issue 28 item 6: the failure path waited for mapping before it closed the input; a second
	// keyframe failing there threw past the close, and the recording (written to a temporary file,
	// renamed on close) was lost. Every keyframe's mapping after the first fails here; the first
	// failure waits until tracking has gone 15 frames further, so that more keyframes are queued
	// behind it (whatever the machine's speed: ASan included).
	TempDir d("system_mapping_failure");
	TSlamJobOptions o = jobFor(d / "run", true);
	o.record = d / "captured.rawlog";
	std::atomic<int> failures{0};
	std::atomic<std::size_t> frames{0};
	o.onFrame = [&](const TFrame&) { frames++; };
	o.onKeyFrame = [&](TKeyFrameId id)
	{
		if (id == 0) return;  // the first keyframe maps: the run goes on until a later one fails
		if (failures == 0)
		{
			const std::size_t until = frames + 15;
			const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
			while (frames < until && std::chrono::steady_clock::now() < deadline)
				std::this_thread::sleep_for(std::chrono::milliseconds(5));
		}
		failures++;
		throw std::runtime_error("injected mapping failure at keyframe " + std::to_string(id));
	};
	EXPECT_THROW(runSlamJob(o), std::runtime_error);
	EXPECT_GE(failures.load(), 2) << "the test needs a second failure behind the first";
	ASSERT_TRUE(fs::exists(o.record)) << "the recording of the frames so far is kept";
	CRawlogSource rec(o.record);
	std::size_t n = 0;
	while (rec.next()) n++;
	EXPECT_GT(n, 0u);
	EXPECT_TRUE(fs::exists(d / "run/trajectory.txt"));
}

namespace
{
// A loop correction that moves the whole map rigidly by T (every keyframe and, with it, every point).
void correctWholeMap(CSparseMap& map, const mrpt::poses::CPose3D& T)
{
	std::map<TKeyFrameId, mrpt::poses::CPose3D> poses;
	for (const auto& k : map.keyFramePoses())
		if (!k.bad) poses[k.id] = T + k.pose;
	map.applyCorrection(poses);
}
}  // namespace

TEST(System, ACorrectionBetweenTrackingAndADelayedKeyFrameCarriesOverToIt)
{
	// Algorithm 1 chooses a keyframe among the frames of an interval that has just closed, so the
	// frame goes into the map frames after it was tracked. A correction landing in between (here a
	// rigid move of the whole map, as a loop correction would make) must carry over to it: inserted
	// at the pose tracked back then, the keyframe and its new points stay in the frame from before
	// and the map holds two copies of the room (issue 28 item 1). Local BA is off: it pulls a new
	// keyframe and its own points back from wherever they were put (measured: even from 2 m and
	// 90 degrees off, the same ATE to 0.1 mm), so here the insertion itself is checked.
	const TTrajectory gt = readTumTrajectory(walkingSequence() + "/groundtruth.txt");
	// `correctAfter`: the frame after whose processing the map is moved (none: a plain run).
	// Returns the ATE of frames and keyframes, and (frame index of the chosen frame, frame index of
	// its insertion) for every keyframe inserted late.
	struct TRun
	{
		double ate = 0, keyFrameAte = 0;
		std::vector<std::pair<std::size_t, std::size_t>> delayed;
	};
	const auto run = [&](std::optional<std::size_t> correctAfter)
	{
		TYesSlamOptions o = walkingSystemOptions();
		o.dense.enabled = false;
		o.mapping.bundleAdjustment = false;
		CYesSlamSystem sys(o);
		auto src = openInputSource(walkingSequence(), o.input);
		std::vector<double> times;
		TRun out;
		for (std::size_t i = 0; auto obs = src->next(); i++)
		{
			times.push_back(mrpt::Clock::toDouble(obs->timestamp));
			const std::size_t before = sys.map().numKeyFrames();
			const TFrameReport r = sys.processFrame(*obs);
			if (!r.keyFrame && sys.map().numKeyFrames() > before)
			{
				const double t = sys.keyFrameTrajectory().back().t;
				const auto j = static_cast<std::size_t>(std::find(times.begin(), times.end(), t) - times.begin());
				out.delayed.emplace_back(j, i);
			}
			if (correctAfter && i == *correctAfter)
				correctWholeMap(sys.mutableMap(), mrpt::poses::CPose3D(0.4, -0.2, 0.3, mrpt::DEG2RAD(20.0),
																	   mrpt::DEG2RAD(-10.0), mrpt::DEG2RAD(5.0)));
		}
		out.ate = computeAte(gt, sys.trajectory(), TEvalOptions()).stats.rmse;
		out.keyFrameAte = computeAte(gt, sys.keyFrameTrajectory(), TEvalOptions()).stats.rmse;
		return out;
	};
	const TRun plain = run(std::nullopt);
	// The map moves after a frame that becomes a keyframe only frames later.
	const auto late = std::find_if(plain.delayed.begin(), plain.delayed.end(),
								   [](const auto& d) { return d.first >= 10 && d.second > d.first; });
	ASSERT_NE(late, plain.delayed.end()) << "the sequence must make a keyframe of an earlier frame";
	const TRun corrected = run(late->first);
	// One rigid alignment fits every pose as well as without the correction. Measured: 5.5 / 4.6 mm
	// (frames / keyframes) either way; with the keyframe inserted at its old pose 5.9 / 140 mm, and
	// with the first frame left at its absolute pose (not hung from keyframe 0) about 60 mm.
	EXPECT_LT(corrected.ate, plain.ate + 0.002);
	EXPECT_LT(corrected.keyFrameAte, plain.keyFrameAte + 0.002);
}

TEST(System, ALoopCorrectionDuringAFramesOwnKeyFrameCarriesOverToTheNextPrediction)
{
	// Sequential mode maps a keyframe (local BA, loop closing) between tracking a frame and
	// handing it to tracking as the last frame. A correction made there moves the map under a pose
	// tracked before it: measured against the moved keyframe, the last frame's pose held the whole
	// correction, and the next frame was predicted that far off (issue 28 item 1 (c)).
	const TTrajectory gt = readTumTrajectory(walkingSequence() + "/groundtruth.txt");
	TYesSlamOptions o = walkingSystemOptions();
	o.dense.enabled = false;
	CYesSlamSystem sys(o);
	bool corrected = false;
	sys.setKeyFrameCallback(
		[&](TKeyFrameId id)
		{
			if (id < 3 || corrected) return;
			corrected = true;
			correctWholeMap(sys.mutableMap(), mrpt::poses::CPose3D(0.4, -0.2, 0.3, mrpt::DEG2RAD(20.0),
																   mrpt::DEG2RAD(-10.0), mrpt::DEG2RAD(5.0)));
		});
	auto src = openInputSource(walkingSequence(), o.input);
	std::size_t after = 0;
	while (auto obs = src->next())
	{
		const bool before = corrected;
		const TFrameReport r = sys.processFrame(*obs);
		if (before)
		{
			EXPECT_TRUE(r.tracked) << "frame " << r.frameId;
			EXPECT_FALSE(r.relocalised) << "frame " << r.frameId << " had to be found again";
			after++;
		}
	}
	ASSERT_TRUE(corrected);
	ASSERT_GT(after, 20u);
	EXPECT_LT(computeAte(gt, sys.trajectory(), TEvalOptions()).stats.rmse, 0.02);
}

// Issue 40 (a), item 3: a correction from another thread (the loop stage, a global BA, an outside
// pose graph) that comes while a frame is being tracked waits until the frame is tracked and its
// keyframe inserted (the map-update lock's protocol). Before, it landed inside track(): the frame
// was matched against points already moved with a prediction from before, anchored to the moved
// keyframe with a stale relative pose, and the next frame could not see that a correction came.
// The test-only hook runs inside tracking, where such a correction would land, and gives it the
// time it needs.
TEST(System, ACorrectionFromAnotherThreadWaitsUntilTheFrameBeingTrackedIsDone)
{
	const TTrajectory gt = readTumTrajectory(walkingSequence() + "/groundtruth.txt");
	TYesSlamOptions o = walkingSystemOptions();
	o.dense.enabled = false;
	CYesSlamSystem sys(o);
	const mrpt::poses::CPose3D T(0.4, -0.2, 0.3, mrpt::DEG2RAD(20.0), mrpt::DEG2RAD(-10.0), mrpt::DEG2RAD(5.0));
	std::thread corrector;
	std::atomic<bool> landed{false};
	bool fired = false, landedInside = false;
	std::size_t calls = 0;
	sys.setTrackingHook(
		[&]
		{
			if (fired || ++calls < 20) return;
			fired = true;
			std::map<TKeyFrameId, mrpt::poses::CPose3D> corrected;
			for (const auto& k : sys.map().keyFramePoses())
				if (!k.bad) corrected[k.id] = T + k.pose;
			corrector = std::thread(
				[&sys, &landed, corrected]
				{
					sys.correctMap(corrected);
					landed = true;
				});
			for (int i = 0; i < 100 && !landed; i++) std::this_thread::sleep_for(std::chrono::milliseconds(5));
			landedInside = landed;
		});
	auto src = openInputSource(walkingSequence(), o.input);
	std::size_t after = 0;
	while (auto obs = src->next())
	{
		const bool before = fired;
		const TFrameReport r = sys.processFrame(*obs);
		if (corrector.joinable()) corrector.join();
		if (!before && !fired) continue;
		EXPECT_TRUE(r.tracked) << "frame " << r.frameId;
		EXPECT_FALSE(r.relocalised) << "frame " << r.frameId << " had to be found again";
		after++;
	}
	ASSERT_TRUE(fired);
	EXPECT_TRUE(landed);
	EXPECT_FALSE(landedInside) << "the correction landed inside the frame's tracking";
	ASSERT_GT(after, 20u);
	// Every pose follows its keyframe through the correction: the trajectory is one rigid piece.
	EXPECT_LT(computeAte(gt, sys.trajectory(), TEvalOptions()).stats.rmse, 0.02);
}

TEST(System, DepthTakenAtAnotherMomentIsMovedToTheColourImages)
{
	// Issue 27: where a TUM folder's depth image was taken at another moment than its colour image
	// (depth.txt's stamps; the simulator's --depth-offset), [Tracking] depthMoment moves each
	// keypoint's depth to the colour image's moment with the motion model. Exact sensor, fast
	// camera; the synchronised twin of the sequence gives the depth at the colour image's moment.
	TempDir d("system_depth_moment");
	TSimOptions sim;
	sim.preset = "static_office";
	sim.frames = 30;
	sim.seed = 3;
	sim.noise = false;
	sim.speed = 4;
	sim.writeRawlog = false;
	sim.outDir = d / "sync";
	runSimulation(sim);
	sim.depthOffsetMs = 16.7;
	sim.outDir = d / "offset";
	runSimulation(sim);
	const auto syncDepth = readTumFileList(d / "sync/depth.txt");

	// Median keypoint depth error against the synchronised depth, over frames with a velocity.
	const auto medianError = [&](bool depthMoment)
	{
		TSlamJobOptions o;
		o.input = d / "offset";
		o.outDir = d / (depthMoment ? "on" : "off");
		o.slam.detector.backend = "none";
		o.slam.system.parallel = false;
		o.slam.tracking.depthMoment = depthMoment;
		std::vector<double> err;
		o.onFrame = [&](const TFrame& f)
		{
			if (f.id < 3) return;
			cv::Mat z;
			cv::imread(d / ("sync/" + syncDepth[f.id].file), cv::IMREAD_UNCHANGED).convertTo(z, CV_32F, 1.0 / 5000);
			for (std::size_t i = 0; i < f.features.keypoints.size(); i++)
			{
				const auto& p = f.features.keypoints[i].pt;
				const float truth = COrbExtractor::depthAt(z, p.x, p.y);
				if (f.features.depth[i] > 0 && truth > 0) err.push_back(std::abs(f.features.depth[i] - truth));
			}
		};
		const auto s = runSlamJob(o);
		EXPECT_EQ(s.stats.trackedFrames, 30u);
		EXPECT_GT(err.size(), 5000u);
		std::nth_element(err.begin(), err.begin() + static_cast<long>(err.size() / 2), err.end());
		return err[err.size() / 2];
	};
	const double off = medianError(false), on = medianError(true);
	EXPECT_GT(off, 0.002) << "the offset moves keypoint depth by millimetres";
	EXPECT_LT(on, 0.3 * off) << "median keypoint depth error, m: " << on << " with depthMoment, " << off << " without";
}

namespace
{
// An exact (noise-free) simulated sequence with exact detections, made for the rolling-shutter tests.
TSimOptions exactSequence(const std::string& preset, std::size_t frames, uint32_t seed, double readoutMs,
						  const std::string& out)
{
	TSimOptions sim;
	sim.preset = preset;
	sim.frames = frames;
	sim.seed = seed;
	sim.noise = false;
	sim.detNoise = "none";
	sim.writeRawlog = false;
	sim.readoutMs = readoutMs;
	sim.outDir = out;
	return sim;
}

// ATE of a sequential yesslam run on `input` with [Tracking] rollingShutter set (-1 = auto).
double ateWithReadout(const std::string& input, const std::string& out, double rollingShutter)
{
	TSlamJobOptions o;
	o.input = input;
	o.outDir = out;
	o.slam.detector.backend = "file";
	o.slam.system.parallel = false;
	o.slam.tracking.rollingShutter = rollingShutter;
	const auto s = runSlamJob(o);
	EXPECT_TRUE(s.evaluated) << s.evalProblem;
	return s.eval.ate.stats.rmse;
}
}  // namespace

TEST(System, ARollingShutterCameraIsTrackedAtEachImagesStamp)
{
	// Issue 27: Kinect and Xtion read their rows over ~28 ms, so a turning camera's image is sheared
	// and no single pose explains it (the real fr1 frames: 3.1 -> 1.8 mm when undone). With
	// [Tracking] rollingShutter = -1 (auto) yesslam takes the readout a simulated sequence states
	// (meta.json) and moves each keypoint to the middle row's moment. Exact sensor, fast camera.
	TempDir d("system_rolling_shutter");
	TSimOptions sim = exactSequence("walking_rpy", 60, 53, 28, d / "rolling");
	sim.speed = 2;
	runSimulation(sim);
	sim.readoutMs = 0;
	sim.outDir = d / "global";
	runSimulation(sim);
	const double global = ateWithReadout(d / "global", d / "global_auto", -1),
				 uncorrected = ateWithReadout(d / "rolling", d / "rolling_off", 0),
				 corrected = ateWithReadout(d / "rolling", d / "rolling_auto", -1);
	const auto used = [&](const std::string& out)
	{ return readTextFile((fs::path(d / out) / "config_used.ini").string()); };
	EXPECT_NE(used("rolling_auto").find("rollingShutter = 0.028"), std::string::npos) << "the sequence's own readout";
	EXPECT_NE(used("global_auto").find("rollingShutter = 0\n"), std::string::npos)
		<< "a global-shutter sequence is not corrected";
	EXPECT_GT(uncorrected, 1.5 * global) << "the shear costs accuracy";
	EXPECT_LT(corrected, 0.6 * uncorrected)
		<< "ATE, m: " << corrected << " corrected, " << uncorrected << " not, " << global << " global shutter";
}

TEST(System, ARollingShutterReadoutIsNeverLongerThanAFrame)
{
	// A camera reads its rows within a frame period. The readout assumed for unknown cameras (28 ms,
	// a 30 Hz Kinect or Xtion) on a faster one scaled the motion model's frame motion by up to 2.8
	// and the correction diverged (a 100 Hz sequence: 24 mm to 1.1 m ATE); it is cut to the time
	// since the previous frame. Exact sensor, the real fr3 path at its 100 Hz stamps, 10 ms readout.
	TempDir d("system_readout_frame");
	TSimOptions sim = exactSequence("walking_xyz", 150, 1, 10, d / "seq");
	sim.trajectoryFile = sharedFile("data/tum_eval_trajectories/fr3_walking_xyz_groundtruth.txt");
	runSimulation(sim);
	const double stated = ateWithReadout(d / "seq", d / "stated", -1),
				 assumed = ateWithReadout(d / "seq", d / "assumed", 0.028);
	EXPECT_LT(assumed, 1.5 * stated + 0.001)
		<< "ATE, m: " << assumed << " with 28 ms assumed, " << stated << " with the stated 10 ms";
}

// Issue 62 item 4: a camera jerked 8 cm sideways and panned 8 degrees within one frame (2.4 m/s, a
// hand-held camera knocked, a robot over a bump) stays tracked, and the online pose, whose filter
// restarts at such an innovation, is not dragged behind by it. A simulated static office (exact
// truth), its camera path with the jerk from frame 40 on; System's refused weak poses are
// Tracker.AWeakSolutionFarFromTheMotionModelIsNotTracked's. (Into a view mostly unseen, 20-40
// degrees, relocalisation places the frame: measured, not tested here.)
TEST(System, ACameraJerkedEightCentimetresAndEightDegreesStaysTracked)
{
	TSimOptions base;
	base.preset = "static_office";
	base.frames = 60;
	const std::string plain = cachedSequence("system_static_office_60", base);
	const TTrajectory gt = readTumTrajectory(plain + "/groundtruth.txt");
	ASSERT_EQ(gt.size(), 60u);
	// Composed in the camera's optical frame: x right (the step), y down (the pan is about it).
	const mrpt::poses::CPose3D jerk(0.08, 0, 0, 0, mrpt::DEG2RAD(8.0), 0);
	TTrajectory jerked = gt;
	for (std::size_t k = 40; k < jerked.size(); k++) jerked[k] = TStampedPose::fromPose(gt[k].t, gt[k].asPose() + jerk);
	TempDir d("jerk");
	writeTumTrajectory(d / "jerk.txt", jerked, "static_office with a jerk at frame 40");
	TSimOptions o = base;
	o.trajectoryFile = d / "jerk.txt";
	const std::string seq = cachedSequence("system_static_office_jerk_8cm_8deg", o);
	TYesSlamOptions so;
	so.detector.backend = "file";
	so.detector.file = seq + "/detections.txt";
	so.system.parallel = false;
	so.dense.enabled = false;
	CYesSlamSystem sys(so);
	auto src = openInputSource(seq, so.input);
	std::size_t n = 0;
	while (auto obs = src->next())
	{
		EXPECT_TRUE(sys.processFrame(*obs).tracked) << "frame " << n;
		n++;
	}
	ASSERT_EQ(n, 60u);
	const TTrajectory truth = readTumTrajectory(seq + "/groundtruth.txt");
	for (const auto& [name, traj] : {std::pair<const char*, TTrajectory>{"trajectory()", sys.trajectory()},
									 {"onlineTrajectory()", sys.onlineTrajectory()},
									 {"smoothedTrajectory()", sys.smoothedTrajectory()}})
	{
		const auto ate = computeAte(truth, traj, TEvalOptions());
		EXPECT_EQ(ate.stats.n, 60u) << name;
		// Measured: 2.5 mm RMSE for the first two, 4.9 and 5.2 mm at worst; the smoothed one's
		// parabola reached across the jerk before its fits ended there: 8.5 mm, 34.6 at worst.
		EXPECT_LT(ate.stats.max, 0.012) << name;
	}
}
