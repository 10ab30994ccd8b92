#include "mrpt_yesslam/system/SlamJob.h"

#include <mrpt/opengl/CPointCloudColoured.h>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "mrpt_yesslam/dense/DenseMapExport.h"
#include "mrpt_yesslam/io/CPrefetchingSource.h"
#include "mrpt_yesslam/io/SceneExport.h"
#include "mrpt_yesslam/io/TextParsing.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
void resolveDetector(CObjectDetector::TOptions& det, const std::string& input)
{
	const fs::path in(input);
	const fs::path beside = fs::is_directory(in) ? in / "detections.txt" : in.parent_path() / "detections.txt";
	if (det.backend == "auto")
	{
		if (!det.file.empty() || fs::exists(beside))
			det.backend = "file";
		else if (useShippedModel(det))	// the configured model, else the shipped Yolo-Fastest
			det.backend = "yolo";
		else
			det.backend = "hog";
	}
	if (det.backend == "file" && det.file.empty())
	{
		if (!fs::exists(beside))
			throw InputError(beside.string(), "not found: the file detector needs [Detector] file or a detections.txt beside the input");
		det.file = beside.string();
	}
	if (det.backend == "yolo" && !useShippedModel(det))
		throw InputError("", "the yolo detector needs [Detector] model (and names): the shipped share/mrpt_yesslam/models was not found (set YESSLAM_SHARE_DIR); or use --detector file, hog or none");
}

namespace
{
// `stop`: why the run ended early (empty: it read the whole input, or --max-frames). stats.json
// then starts with "complete": false, the reason and the frames done, so a run cut short is never
// taken for a whole one.
void writeOutputs(const CYesSlamSystem& sys, const std::string& dir, TSlamJobSummary& sum, const std::string& stop = {})
{
	const fs::path d(dir);
	std::string json = sys.statsJson();
	std::string head = std::string("{\n  \"complete\": ") + (stop.empty() ? "true" : "false") + ",\n";
	if (!stop.empty()) head += "  \"stop_reason\": \"" + jsonEscape(stop) + "\",\n";
	json = head + json.substr(json.find('\n') + 1);
	writeTumTrajectory((d / "trajectory.txt").string(), sys.trajectory(), "camera pose of every frame (T_w_c), world = first keyframe");
	writeTumTrajectory((d / "keyframes.txt").string(), sys.keyFrameTrajectory(), "keyframe poses (T_w_c)");
	auto scene = sys.buildScene();
	if (sys.denseMapper())
	{
		// The dense map from the keyframes' final poses: labelled cloud, OctoMaps, and the octree in
		// the scene (coloured by label) so that yesslam-render pictures it.
		const TDenseMap dm = sys.buildDenseMap();
		const auto& names = sys.detector()->classNames();
		writeDenseCloudPly((d / "dense_cloud.ply").string(), dm.cloud, names);
		writeSemanticOcTree((d / "map.ot").string(), *dm.octree);
		writeOccupancyBt((d / "map.bt").string(), *dm.octree);
		scene->insert(semanticOcTreeObject(*dm.octree, names));
		// The dense cloud too, in its colours ("yesslam-render --hide octomap" shows it alone).
		auto cloud = mrpt::opengl::CPointCloudColoured::Create();
		cloud->setName("dense_cloud");
		cloud->setPointSize(2.0f);
		for (std::size_t i = 0; i < dm.cloud.size(); i++)
		{
			const auto& p = dm.cloud.xyz[i];
			const auto& c = dm.cloud.bgr[i];
			cloud->push_back(p.x, p.y, p.z, c[2] / 255.f, c[1] / 255.f, c[0] / 255.f);
		}
		scene->insert(cloud);
		sum.dense.cloudPoints = dm.cloud.size();
		sum.dense.outliersRemoved = dm.outliersRemoved;
		sum.dense.buildMs = dm.buildMs;
		for (auto it = dm.octree->begin_leafs(), end = dm.octree->end_leafs(); it != end; ++it)
			(dm.octree->isNodeOccupied(*it) ? sum.dense.occupiedLeaves : sum.dense.freeLeaves)++;
		std::error_code ec;
		sum.dense.plyBytes = fs::file_size(d / "dense_cloud.ply", ec);
		sum.dense.otBytes = fs::file_size(d / "map.ot", ec);
		sum.dense.btBytes = fs::file_size(d / "map.bt", ec);
	}
	saveSceneAtomically(*scene, (d / "map.3Dscene").string());
	writeFileAtomically((d / "stats.json").string(), json);
	writeFileAtomically((d / "config_used.ini").string(), "; the configuration of this run\n" + sys.options().dump());
	sum.stats = sys.stats();
}
}  // namespace

TSlamJobSummary runSlamJob(
	const TSlamJobOptions& o, const std::function<void(std::size_t, std::size_t, const std::string&)>& progress,
	const std::function<bool()>& cancel)
{
	TSlamJobSummary sum;
	TYesSlamOptions opts = o.slam;
	resolveDetector(opts.detector, o.input);
	std::unique_ptr<CInputSource> src = openInputSource(o.input, opts.input);
	if (opts.input.prefetch > 0) src = std::make_unique<CPrefetchingSource>(std::move(src), static_cast<std::size_t>(opts.input.prefetch));
	sum.groundTruth = o.groundTruth.empty() ? findGroundTruthFor(o.input) : o.groundTruth;
	TTrajectory gt;
	if (!sum.groundTruth.empty()) gt = readTumTrajectory(sum.groundTruth);	// bad ground truth: fail before the long run
	// The system (detector model, options) first: a run that cannot start leaves no output folder.
	CYesSlamSystem sys(opts);
	std::error_code ec;
	fs::create_directories(o.outDir, ec);
	if (!fs::is_directory(o.outDir)) throw InputError(o.outDir, "cannot create the output folder" + (ec ? " (" + ec.message() + ")" : std::string()));
	// An evaluation left by an earlier run in this folder must not pass for this run's.
	fs::remove(fs::path(o.outDir) / "eval.json", ec);

	if (o.onFrame) sys.setFrameCallback(o.onFrame);
	sum.detector = sys.detector()->description();
	const auto t0 = std::chrono::steady_clock::now();
	std::size_t done = 0;
	try
	{
		while (!(o.maxFrames && done >= o.maxFrames))
		{
			if (cancel && cancel())
			{
				sum.interrupted = true;
				break;
			}
			auto obs = src->next();
			if (!obs) break;
			const TFrameReport r = sys.processFrame(*obs);
			done++;
			if (progress)
			{
				const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
				char buf[160];
				std::snprintf(
					buf, sizeof(buf), "%.1f fps  %s  kf %zu  inliers %zu", s > 0 ? static_cast<double>(done) / s : 0.0,
					r.tracked ? "tracking" : (r.frameId == 0 ? "initialising" : "LOST"), sys.map().numKeyFrames(), r.inliers);
				progress(done, src->sizeHint(), buf);
			}
		}
	}
	catch (const std::exception& e)
	{
		// A bad frame, or a failure of the mapping stage: keep what was done up to here.
		try
		{
			sys.waitForMapping();
		}
		catch (const std::exception&)
		{
			// Already failing: the first error is the one reported.
		}
		writeOutputs(sys, o.outDir, sum, "error at frame " + std::to_string(done) + ": " + exceptionSummary(e.what()));
		throw;
	}
	sys.waitForMapping();
	sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
	writeOutputs(sys, o.outDir, sum, sum.interrupted ? "interrupted after " + std::to_string(done) + " frames" : std::string());
	if (!gt.empty() && sum.stats.frames > 0)
	{
		try
		{
			TEvalOptions eo;
			sum.eval = evaluateTrajectories(gt, sys.trajectory(), eo, sum.groundTruth, "trajectory.txt");
			sum.evaluated = true;
			writeFileAtomically((fs::path(o.outDir) / "eval.json").string(), formatEvalJson(sum.eval));
		}
		catch (const std::exception& e)
		{
			sum.evalProblem = e.what();
		}
	}
	return sum;
}
}  // namespace mrpt_yesslam
