#include "mrpt_yesslam/jobs/SlamJob.h"
#include "mrpt_yesslam/jobs/SlamOutputs.h"
#include "SlamJobInput.h"

#include <mrpt/opengl/CPointCloudColoured.h>

#include <chrono>
#include <optional>
#include <cstdio>
#include <deque>
#include <exception>
#include <mutex>
#include <filesystem>
#include <fstream>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <utility>

#include "mrpt_yesslam/dense/DenseMapExport.h"
#include "mrpt_yesslam/eval/TrajectoryPlot.h"
#include "mrpt_yesslam/io/COpenNI2Source.h"
#include "mrpt_yesslam/io/CPacedSource.h"
#include "mrpt_yesslam/io/CPrefetchingSource.h"
#include "mrpt_yesslam/io/CRawlogWriter.h"
#include "mrpt_yesslam/io/RgbdCamera.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/io/SceneExport.h"
#include "mrpt_yesslam/system/CMapCheckpointer.h"
#include "mrpt_yesslam/system/CRunJournal.h"
#include "mrpt_yesslam/system/SlamExport.h"
#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/io/WorldFrame.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
using job_detail::CRecorder;
using job_detail::openInput;
using job_detail::TInputChain;

namespace
{
// Frames with depth whose median depth judges the depth scale, and the range it must fall in.
constexpr std::size_t kDepthScaleFrames = 5;
constexpr double kLeastMedianDepth = 0.1, kMostMedianDepth = 20;

void checkDepthScale(std::vector<double> medians, const std::string& input)
{
	auto mid = medians.begin() + static_cast<std::ptrdiff_t>(medians.size() / 2);
	std::nth_element(medians.begin(), mid, medians.end());
	if (*mid >= kLeastMedianDepth && *mid <= kMostMedianDepth) return;
	throw InputError(input, "the median depth of its first " + std::to_string(medians.size()) +
								" frames with depth is " + formatNumber(*mid) + " m, which no RGB-D camera measures (" +
								formatNumber(kLeastMedianDepth) + "-" + formatNumber(kMostMedianDepth) +
								" m): the depth scale is wrong (units a metre: TUM 5000, OpenNI 1000; set by a TUM "
								"folder's calibration, a camera file's last number or the rawlog's range units)");
}
}  // namespace

const char* secondInterruptNote(ESlamJobPhase phase)
{
	// The final mapping is not cut short (a half-done local BA leaves keyframes and points
	// disagreeing); what a second Ctrl-C saves is the time of the slow outputs after it.
	switch (phase)
	{
		case ESlamJobPhase::FinalMapping:
			return "second Ctrl-C: the final mapping runs to its end, then only the trajectories, frames.csv, "
				   "stats.json and the configuration "
				   "are written (the dense map, the map file and the scene are skipped; Ctrl-C once more kills at "
				   "once)";
		case ESlamJobPhase::Saving:
			return "second Ctrl-C: the file being written is finished, the rest skipped (Ctrl-C once more kills at "
				   "once)";
		case ESlamJobPhase::Frames: break;
	}
	return "second Ctrl-C: the outputs not yet begun will be skipped after the final mapping (Ctrl-C once more kills "
		   "at once)";
}

TSlamJobSummary runSlamJob(const TSlamJobOptions& o,
						   const std::function<void(std::size_t, std::size_t, const std::string&)>& progress,
						   const std::function<bool()>& cancel, const std::function<bool()>& abortSaving)
{
	TSlamJobSummary sum;
	TYesSlamOptions opts = o.slam;
	resolveDetector(opts.detector, inputFilePath(o.input));
	sum.groundTruth = o.groundTruth.empty() && !inputFilePath(o.input).empty()
						  ? findGroundTruthFor(inputFilePath(o.input))
						  : o.groundTruth;
	TTrajectory gt;
	if (!sum.groundTruth.empty())
	{
		sum.groundTruthFormat = resolveGroundTruthFormat(sum.groundTruth, o.groundTruthFormat);
		gt = readGroundTruth(sum.groundTruth, sum.groundTruthFormat);  // bad ground truth: fail before the long run
	}
	if (!o.saveMap.empty())
	{
		// Found out now, not after an hour of mapping.
		// Its folder is made, as --out's is (the map inside the run's new output folder is usual).
		const fs::path dir = fs::path(o.saveMap).parent_path();
		std::error_code made;
		if (!dir.empty() && !fs::is_directory(dir)) fs::create_directories(dir, made);
		if (!dir.empty() && !fs::is_directory(dir))
			throw InputError(o.saveMap, "cannot save the map there: its folder cannot be made" +
											(made ? " (" + made.message() + ")" : std::string()));
		if (fs::is_directory(o.saveMap)) throw InputError(o.saveMap, "cannot save the map there: it is a folder");
		// A folder that exists but takes no files (/proc, read-only media, no permission).
		const fs::path probe = (dir.empty() ? fs::path(".") : dir) / (".yesslam_probe_" + std::to_string(::getpid()));
		{
			std::ofstream f(probe);
			if (!f) throw InputError(o.saveMap, "cannot save the map there: the folder takes no new files");
		}
		std::error_code rm;
		fs::remove(probe, rm);
		if (!o.record.empty() && fs::weakly_canonical(o.record, rm) == fs::weakly_canonical(o.saveMap, rm))
			throw InputError(o.saveMap, "--save-map and --record name the same file: one would overwrite the other");
	}
	if (!o.record.empty())
	{
		std::error_code ec;
		if (fs::is_directory(o.record)) throw InputError(o.record, "cannot record there: it is a folder");
		if (!inputFilePath(o.input).empty() && fs::exists(o.record) &&
			fs::equivalent(o.record, inputFilePath(o.input), ec))
			throw InputError(o.record, "--record names the input itself: recording would destroy what is being read");
		if (fs::exists(o.record) && !o.overwrite)
			throw InputError(
				o.record,
				"exists: a recording is not replaced unless asked (--overwrite), choose another file or remove it");
	}
	if (o.skipFrames && (isOpenNI2Input(o.input) || o.live.realtime))
		throw InputError("", "skipping frames is for recorded input read in order, not for live or real-time input");
	if (opts.system.localizeOnly)
	{
		if (o.loadMap.empty())
			throw InputError("", "localisation only needs a map to localise in (--load-map MAP.ysm)");
		opts.dense.enabled = false;  // no keyframes: nothing to build a dense map from
	}
	// The camera's rolling shutter: what the input says (a simulated sequence), else what its
	// camera is known to have (TUM presets, Bonn folders, a camera file's readout line); a camera
	// of unknown readout (rawlogs, OpenNI2 devices, other folders) is not corrected: a 28 ms
	// correction on a global-shutter camera would shear every keypoint by the motion model.
	// config_used.ini then records the value the run used.
	sum.readout = resolveReadout(opts.tracking.rollingShutter, o.input, opts.input);
	if (sum.readout.source == "none")
	{
		// Issue 70: a Kinect v1 or Xtion-class camera run without its readout lost a third of the
		// accuracy and nobody was told.
		sum.warnings.push_back("the camera's rolling-shutter readout is not known for " + o.input +
							   ": no correction (on a rolling-shutter camera such as a Kinect v1 or Xtion that costs "
							   "about a third of the accuracy); give it as "
							   "a camera file's readout line (seconds, or kinect1 / xtion / global), --camera "
							   "fr1|fr2|fr3, or [Tracking] rollingShutter");
	}
	opts.tracking.rollingShutter = sum.readout.seconds;
	// An option that cannot apply is not recorded as applied (config_used.ini is what the run used).
	if (!opts.input.camera.empty() && !fs::is_directory(o.input) && !isOpenNI2Input(o.input))
	{
		sum.warnings.push_back("[Input] camera (--camera) '" + opts.input.camera +
							   "' is for TUM folders and OpenNI2 input and was not used: the frames of " + o.input +
							   " carry their own camera");
		opts.input.camera.clear();
	}
	// The system (detector model, options) and the map first: a run that cannot start leaves no
	// output folder.
	CYesSlamSystem sys(opts);
	if (!o.loadMap.empty())
	{
		sys.loadMap(o.loadMap);
		sum.mapFiles.loadedKeyFrames = sys.map().numKeyFrames();
		sum.mapFiles.loadedPoints = sys.map().numPoints();
	}
	// The recording is opened before the input starts delivering, written by whoever reads the
	// frames first (the capture thread for live input), and committed however the run ends.
	std::unique_ptr<CRecorder> recorder;
	if (!o.record.empty())
	{
		makeParentFolder(o.record);
		recorder = std::make_unique<CRecorder>(o.record);
	}
	std::function<void(const mrpt::obs::CObservation3DRangeScan::Ptr&)> record;
	if (recorder) record = [&recorder](const mrpt::obs::CObservation3DRangeScan::Ptr& f) { recorder->add(f); };
	TInputChain in = openInput(o, opts, record);
	if (in.live) record = nullptr;  // the capture thread records
	CInputSource* src = in.source.get();
	sum.input.live = in.live != nullptr;
	sum.input.device = in.device;
	// Before any output: what the input did, and the recording closed (renamed into place).
	auto closeInput = [&]
	{
		if (in.live)
		{
			in.live->stop();
			sum.input.stats = in.live->stats();
			sum.input.disconnected = in.disconnected();
		}
		if (recorder)
		{
			// The capture thread may still be writing: it is stopped first.
			in.source.reset();
			in.live = nullptr;
			sum.input.recorded = recorder->finish();
			const auto camera = recorder->camera();
			recorder.reset();
			// The input's ground truth goes with the recording, where findGroundTruthFor looks for it
			// ("<name>_groundtruth.txt"), so the recording evaluates as its input did (issue 43).
			// A failure here costs the copy (a warning), never the run's outputs.
			const std::string gtIn = isOpenNI2Input(o.input) ? std::string() : findGroundTruthFor(o.input);
			const TOutputTarget target = outputTarget(o.record);
			const fs::path rec(o.record);
			const fs::path gtOut = rec.parent_path() / (rec.stem().string() + "_groundtruth.txt");
			std::error_code gec;
			if (sum.input.recorded > 0 && !target.direct && fs::is_regular_file(target.path, gec))
			{
				// The camera's readout goes with it too (a rawlog's frames hold no readout; issue 62 item 5).
				if (camera) try
					{
						TRgbdCamera c;
						c.intrinsics = *camera;
						if (sum.readout.source != "none")
						{
							c.readout = sum.readout.seconds;
							c.readoutSource = sum.readout.source;
						}
						writeFileAtomically(recordingCameraPath(o.record),
											formatCameraFile(c, "the camera of " + rec.filename().string() +
																	" (yesslam --record, from " + o.input + ")"));
					}
					catch (const std::exception& e)
					{
						std::error_code rec_ec;
						fs::remove(recordingCameraPath(o.record),
								   rec_ec);  // an earlier recording's would pass for this one's
						sum.warnings.push_back(
							"the camera file was not written beside the recording (a replay will not know its "
							"readout): " +
							exceptionSummary(e.what()));
					}
				try
				{
					if (!gtIn.empty())
						writeFileAtomically(gtOut.string(), readTextFile(gtIn));
					else if (fs::exists(gtOut, gec))
						sum.warnings.push_back(
							gtOut.string() +
							" is from an earlier recording: the input of this one had no ground truth");
				}
				catch (const std::exception& e)
				{
					sum.warnings.push_back("the ground truth was not copied beside the recording: " +
										   exceptionSummary(e.what()));
				}
			}
		}
	};
	// On a failure: the recording of the frames read is committed if it can be; the first error is the one reported.
	auto closeInputQuietly = [&]
	{
		try
		{
			closeInput();
		}
		catch (const std::exception&)
		{
		}
	};
	// Skipped before any output: a skip past the end of the input is an error, not an empty run;
	// so is a skip that leaves no frame (the first one is read here to know).
	std::size_t skipped = 0;
	while (skipped < o.skipFrames && src->next()) skipped++;
	mrpt::obs::CObservation3DRangeScan::Ptr first, ahead;  // ahead: the next frame, read while this one is processed
	std::exception_ptr aheadError;                         // reading it failed
	if (skipped == o.skipFrames && o.skipFrames > 0)
	{
		try
		{
			first = src->next();
		}
		catch (...)
		{
			closeInput();  // commits the recording of what was read
			throw;
		}
		if (!first) skipped = o.skipFrames + 1;
	}
	if (skipped != o.skipFrames)
	{
		closeInput();
		const std::size_t held = std::min(skipped, o.skipFrames);
		throw InputError(o.input, "--skip-frames " + std::to_string(o.skipFrames) +
									  " skips every frame: the input holds only " + std::to_string(held) +
									  (held == 1 ? " frame" : " frames"));
	}
	// The output folder and the journal; failing, the recording of the frames read so far is committed first.
	std::optional<CRunJournal> journal;
	try
	{
		std::error_code ec;
		fs::create_directories(o.outDir, ec);
		if (!fs::is_directory(o.outDir))
			throw InputError(o.outDir,
							 "cannot create the output folder" + (ec ? " (" + ec.message() + ")" : std::string()));
		// What an earlier run left in this folder must not pass for this run's: an evaluation or a
		// dense map this one may not write, and the outputs it writes only at its end (a killed run
		// leaves its journal and nothing else; a second Ctrl-C skips the slow ones).
		for (const char* f :
			 {"eval.json", "eval_online.json", "eval_smoothed.json", "ate.png", "dense_cloud.ply", "map.ot", "map.bt",
			  "map_2d.gridmap", "map_2d.pgm", "map_2d.yaml", "map_2d.png", "trajectory.txt", "trajectory_smoothed.txt",
			  "keyframes.txt", "loop_candidates.csv", "config_used.ini", "map.3Dscene"})
			fs::remove(fs::path(o.outDir) / f, ec);
		// The online poses and frames.csv as the run goes, stats.json "complete": false until the end.
		journal.emplace(o.outDir);
	}
	catch (...)
	{
		closeInputQuietly();
		throw;
	}

	// The map saved in the background every [System] checkpointSeconds (a loaded map only localised
	// in does not change); stopped, with its figures kept, before the run's own outputs.
	std::optional<CMapCheckpointer> checkpoints;
	// A file only: a pipe or a device (/dev/stdout) would get a map per checkpoint.
	if (!o.saveMap.empty() && opts.system.checkpointSeconds > 0 && !opts.system.localizeOnly &&
		[&]
		{
			const auto t = outputTarget(o.saveMap);
			return !t.direct && t.fd < 0;
		}())
		checkpoints.emplace(sys, o.saveMap, opts.system.checkpointSeconds);
	const auto endCheckpoints = [&]
	{
		if (!checkpoints) return;
		checkpoints->stop();
		const auto c = checkpoints->stats();
		sum.mapFiles.checkpointSeconds = opts.system.checkpointSeconds;
		sum.mapFiles.checkpoints = c.saved;
		sum.mapFiles.checkpointFailures = c.failed;
		sum.mapFiles.checkpointOctrees = c.octrees;
		sum.mapFiles.checkpointMaxMs = c.maxMs;
		sum.mapFiles.checkpointError = c.lastError;
		if (c.failed > 0)
			sum.warnings.push_back(std::to_string(c.failed) + " of " + std::to_string(c.saved + c.failed) +
								   " map checkpoints failed, the last: " + c.lastError);
	};
	if (o.onFrame) sys.setFrameCallback(o.onFrame);
	if (o.onKeyFrame) sys.setKeyFrameCallback(o.onKeyFrame);
	if (o.onLoop) sys.setLoopCallback(o.onLoop);
	sum.detector = sys.detector()->description();
	const auto t0 = std::chrono::steady_clock::now();
	std::size_t done = 0;
	std::vector<double> depthMedians;  // each frame's median depth: is the depth scale plausible?
	bool journalWarned = false;
	if (o.onPhase) o.onPhase(ESlamJobPhase::Frames);
	try
	{
		while (!(o.maxFrames && done >= o.maxFrames))
		{
			if (cancel && cancel())
			{
				sum.interrupted = true;
				break;
			}
			// A frame read ahead that could not be read fails here, where it would have been read.
			if (aheadError) std::rethrow_exception(std::exchange(aheadError, nullptr));
			auto obs = first ? std::move(first) : ahead ? std::move(ahead) : src->next();
			if (!obs) break;
			// Recorded input: the next frame is read now and its detection started, so that it overlaps this frame's
			// tracking as well as its own ORB extraction (issue 41: the frame waited for the detector). Live input is
			// not read ahead: that would hold this frame until the camera delivers the next.
			if (!in.live && !(o.maxFrames && done + 1 >= o.maxFrames)) try
				{
					sys.detectAhead(*obs, 0);  // this frame first (already under way unless it is the first)
					if ((ahead = src->next())) sys.detectAhead(*ahead, 1);
				}
				catch (...)
				{
					aheadError = std::current_exception();  // after this frame, as without reading ahead
				}
			if (const double md = medianDepth(*obs); md > 0)
			{
				depthMedians.push_back(md);  // frames without depth say nothing of its scale
				// A depth scale no camera can have (metres read as millimetres, or the reverse) stops the run
				// at once: every pose and map from it would be wrong (issue 63 item 6).
				if (depthMedians.size() == kDepthScaleFrames) checkDepthScale(depthMedians, o.input);
			}
			if (record) record(obs);
			const std::optional<double> depthTime = src->depthTime(observationTime(*obs));
			// Said, not silently ignored (issue 42): only inputs that stamp their depth images apart
			// from the colour ones (TUM folders: depth.txt) give the option anything to move.
			if (done == 0 && opts.tracking.depthMoment && !depthTime)
				sum.warnings.push_back("[Tracking] depthMoment does nothing for " + o.input +
									   ": it gives no depth-image stamps of its own (only TUM folders do, with "
									   "depth.txt); the depth is taken as of the colour image's moment");
			const TFrameReport r = sys.processFrame(*obs, depthTime);
			done++;
			if (!journal->update(sys) && !journal->failure().empty() && !journalWarned)
			{
				sum.warnings.push_back(journal->failure() + " (the run went on; its outputs at the end are complete)");
				journalWarned = true;
			}
			if (checkpoints) checkpoints->tick();
			if (progress)
			{
				const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
				const char* state = r.tracked ? "tracking" : (r.frameId == 0 ? "initialising" : "LOST");
				char buf[200];
				if (in.live)
				{
					const TLiveStats ls = in.live->stats();
					std::snprintf(buf, sizeof(buf), "capture %.1f fps  processed %.1f fps  dropped %zu  %s  kf %zu",
								  ls.captureFps, s > 0 ? static_cast<double>(done) / s : 0.0, ls.dropped, state,
								  sys.map().numKeyFrames());
				}
				else
					std::snprintf(buf, sizeof(buf), "%.1f fps  %s  kf %zu  inliers %zu",
								  s > 0 ? static_cast<double>(done) / s : 0.0, state, sys.map().numKeyFrames(),
								  r.inliers);
				// The total this run will process: the input's frames after the skip, at most --max-frames.
				std::size_t total = src->sizeHint();
				if (total > o.skipFrames) total -= o.skipFrames;
				if (o.maxFrames && (total == 0 || total > o.maxFrames)) total = o.maxFrames;
				progress(done, total, buf);
			}
		}
	}
	catch (const std::exception& e)
	{
		// A bad frame, or a failure of the mapping stage: keep what was done up to here. The input
		// first (it commits the recording): waiting for mapping may throw again (another keyframe
		// that failed), and the recording of the frames so far must not be lost with it.
		closeInputQuietly();
		sys.settle();  // every stage done before the outputs (its failures are not this error)
		endCheckpoints();
		releaseBeforeOutputs(sys);  // no frame is processed after this
		journal->close();
		writeSlamOutputs(sys, o.outDir, sum,
						 "error at frame " + std::to_string(done) + ": " + exceptionSummary(e.what()), o.saveMap);
		throw;
	}
	const std::size_t skippedEntries = src->skipped();
	try
	{
		closeInput();
		if (o.onPhase) o.onPhase(ESlamJobPhase::FinalMapping);
		sys.waitForMapping();
	}
	catch (const std::exception& e)
	{
		// The recording or the final mapping failed: the outputs of the frames done say so (the
		// journal alone would say the run has not ended).
		sys.settle();
		endCheckpoints();
		releaseBeforeOutputs(sys);
		journal->close();
		writeSlamOutputs(sys, o.outDir, sum,
						 "error after frame " + std::to_string(done) + ": " + exceptionSummary(e.what()), o.saveMap);
		throw;
	}
	sum.input.skippedEntries = skippedEntries;
	if (!sum.input.live && fs::is_directory(o.input)) sum.input.stats.unpaired = skippedEntries;
	if (skippedEntries > 0 && !sum.input.live)
		sum.warnings.push_back(
			fs::is_directory(o.input)
				? std::to_string(skippedEntries) + " colour image" + (skippedEntries == 1 ? " has" : "s have") +
					  " no depth image within [Input] maxDiff " + formatNumber(opts.input.maxDiff) + " s in " +
					  o.input + " and " + (skippedEntries == 1 ? "was" : "were") + " not processed"
				: std::to_string(skippedEntries) + " entries of " + o.input +
					  " are not RGB-D frames and were not processed");
	if (depthMedians.empty() && done > 0)
		sum.typicalDepth = 0;  // no frame had any depth: implausibleDepthReason says so
	else if (!depthMedians.empty())
	{
		auto mid = depthMedians.begin() + static_cast<std::ptrdiff_t>(depthMedians.size() / 2);
		std::nth_element(depthMedians.begin(), mid, depthMedians.end());
		sum.typicalDepth = *mid;
		const std::string why = implausibleDepthReason(sum.typicalDepth);
		if (!why.empty()) sum.warnings.push_back(why);
	}
	sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
	std::string stop = sum.interrupted ? "interrupted after " + std::to_string(done) + " frames" : std::string();
	if (sum.input.disconnected) stop = "the camera stopped delivering frames after " + std::to_string(done) + " frames";
	if (o.onPhase) o.onPhase(ESlamJobPhase::Saving);
	endCheckpoints();
	releaseBeforeOutputs(sys);
	journal->close();
	writeSlamOutputs(sys, o.outDir, sum, stop, o.saveMap, abortSaving);
	// A pass that was never placed in the loaded map has no pose to give: an error, not identity
	// poses and an ATE over them (the outputs say so too: no pose, every frame "none").
	if (!o.loadMap.empty() && sum.stats.frames > 0 && sum.stats.trackedFrames == 0 && !sum.interrupted)
		throw InputError(o.loadMap,
						 "never localised in the map: none of the " + std::to_string(sum.stats.frames) + " frames of " +
							 o.input +
							 " was recognised (is it the place the map was made in?); the outputs hold no pose");
	// A run that never started its map has nothing to give (issue 43): an error with the likely
	// reason, not an exit 0 over empty outputs.
	if (o.loadMap.empty() && sum.stats.frames > 0 && sum.stats.keyFrames == 0 && !sum.interrupted &&
		!sum.input.disconnected)
	{
		std::string why = implausibleDepthReason(sum.typicalDepth);
		if (why.empty() && sum.typicalDepth > opts.tracking.maxDepth)
			why = "the median depth is " + formatNumber(sum.typicalDepth) + " m, beyond [Tracking] maxDepth " +
				  formatNumber(opts.tracking.maxDepth) + " m: is the depth scale right?";
		if (why.empty()) why = "too few features with depth to start a map (blank, dark or textureless frames?)";
		throw InputError(o.input, "no map was made: none of the " + std::to_string(sum.stats.frames) +
									  " frames could start one; " + why + "; the outputs hold no pose");
	}
	if (!gt.empty() && sum.stats.frames > 0)
	{
		try
		{
			TEvalOptions eo;
			sum.eval = evaluateTrajectories(gt, sys.trajectory(), eo, sum.groundTruth, "trajectory.txt");
			sum.evaluated = true;
			writeFileAtomically((fs::path(o.outDir) / "eval.json").string(), formatEvalJson(sum.eval));
			// The picture people look at first (yesslam-eval --plot draws the same).
			plotAteTopDown(sum.eval.ate, gt, (fs::path(o.outDir) / "ate.png").string(),
						   "trajectory.txt vs " + fs::path(sum.groundTruth).filename().string());
			sum.evalOnline =
				evaluateTrajectories(gt, sys.onlineTrajectory(), eo, sum.groundTruth, "trajectory_online.txt");
			sum.evaluatedOnline = true;
			writeFileAtomically((fs::path(o.outDir) / "eval_online.json").string(), formatEvalJson(sum.evalOnline));
			sum.evalSmoothed =
				evaluateTrajectories(gt, sys.smoothedTrajectory(), eo, sum.groundTruth, "trajectory_smoothed.txt");
			sum.evaluatedSmoothed = true;
			writeFileAtomically((fs::path(o.outDir) / "eval_smoothed.json").string(), formatEvalJson(sum.evalSmoothed));
		}
		catch (const std::exception& e)
		{
			sum.evalProblem = e.what();
		}
	}
	return sum;
}
}  // namespace mrpt_yesslam
