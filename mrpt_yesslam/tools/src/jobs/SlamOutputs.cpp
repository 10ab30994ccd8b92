#include "mrpt_yesslam/jobs/SlamOutputs.h"

#include <mrpt/opengl/CPointCloudColoured.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <set>
#include <vector>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "mrpt_yesslam/dense/DenseMapExport.h"
#include "mrpt_yesslam/io/SceneExport.h"
#include "mrpt_yesslam/io/WorldFrame.h"
#include "mrpt_yesslam/mapio/GridMapFiles.h"
#include "mrpt_yesslam/system/CYesSlamSystem.h"
#include "mrpt_yesslam/system/SlamExport.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/TextParsing.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
// The outputs (the dense map's build above all) were the run's peak of memory (issue 41 item 5): before them the frames
// no output needs and the detector's network go, and glibc gives back what its per-thread arenas hold free (the stages'
// threads freed it; docs/benchmarks.md, "Memory at the outputs").
void releaseBeforeOutputs(CYesSlamSystem& sys)
{
	sys.releaseRecentFrames();
	sys.releaseDetectorModel();
#if defined(__GLIBC__)
	malloc_trim(0);
#endif
}

namespace
{
// map_2d.gridmap, .pgm, .yaml and .png from the dense map's octree (issue 67): a failure is reported
// in the summary, not the run's.
void writeGrid2D(const CYesSlamSystem& sys, const TWorldFrame& world, const TTrajectory& trajectory,
				 const TDenseMap& dm, const std::string& base, TSlamJobSummary& sum)
{
	const auto& go = sys.options().grid;
	if (!go.enabled) return;
	if (world.kind != TWorldFrame::EKind::ZUp)
	{
		sum.dense.gridProblem = "no 2D grid: it needs the z-up world frame ([System] worldFrame = zup)";
		return;
	}
	std::set<std::uint8_t> dynamicLabels;
	const CObjectDetector& det = *sys.detector();
	for (std::size_t c = 0; c < det.classNames().size() && c < 255; c++)
		if (det.isDynamicClass(static_cast<int>(c))) dynamicLabels.insert(static_cast<std::uint8_t>(c + 1));
	// The path drawn is every pose; the footprint cleared only where tracking measured the pose (a
	// coasted one may have drifted anywhere).
	std::set<double> trackedStamps;
	for (const auto& row : sys.frameLog())
		if (row.tracked) trackedStamps.insert(row.timestamp);
	std::vector<mrpt::math::TPoint3D> path, tracked;
	for (const auto& p : trajectory)
	{
		path.emplace_back(p.tx, p.ty, p.tz);
		const auto at = trackedStamps.lower_bound(p.t - 1e-6);
		if (at != trackedStamps.end() && *at <= p.t + 1e-6) tracked.emplace_back(p.tx, p.ty, p.tz);
	}
	// Without a floor the world's origin is the first camera: the floor is assumed cameraHeight below it.
	const double floorZ = world.floorSeen ? 0.0 : -go.cameraHeight;
	try
	{
		const TOccupancyGrid2D g =
			COccupancyGridBuilder(go).build(*dm.octree, dynamicLabels, tracked, floorZ, world.floorSeen);
		writeGridMapFiles(base, g, path);
		sum.dense.gridOccupied = g.count(TOccupancyGrid2D::kOccupied);
		sum.dense.gridFree = g.count(TOccupancyGrid2D::kFree);
		sum.dense.gridUnknown = g.count(TOccupancyGrid2D::kUnknown);
		sum.dense.gridResolution = g.resolution;
		sum.dense.gridFloorSeen = g.floorSeen;
	}
	catch (const std::exception& e)
	{
		sum.dense.gridProblem = std::string("no 2D grid: ") + e.what();
	}
}
}  // namespace

void writeSlamOutputs(const CYesSlamSystem& sys, const std::string& dir, TSlamJobSummary& sum, const std::string& stop,
					  const std::string& mapPath, const std::function<bool()>& abort)
{
	const fs::path d(dir);
	TStatsContext ctx;
	ctx.loopClosing = sys.options().loop.detection.enabled;
	ctx.denseMap = sys.denseMapper() != nullptr;
	ctx.dynamicFilter = sys.options().system.dynamicFilter;
	ctx.keyFramePolicy = sys.options().keyFrames.policy;
	const std::string body = formatStatsJson(sys.stats(), ctx);
	const auto& in = sum.input;
	const auto statsJson = [&](const std::string& reason)
	{
		std::string head = std::string("{\n  \"complete\": ") + (reason.empty() ? "true" : "false") + ",\n";
		if (!reason.empty()) head += "  \"stop_reason\": \"" + jsonEscape(reason) + "\",\n";
		char buf[512];
		std::snprintf(buf, sizeof(buf),
					  "  \"input\": {\"live\": %s, \"captured_frames\": %zu, \"delivered_frames\": %zu, "
					  "\"dropped_frames\": %zu, \"waiting_frames\": %zu, "
					  "\"unpaired_frames\": %zu, \"skipped_entries\": %zu, \"capture_fps\": %.2f, \"disconnected\": "
					  "%s, \"recorded_frames\": %zu, "
					  "\"typical_depth_m\": %.3f",
					  in.live ? "true" : "false", in.stats.captured, in.stats.delivered, in.stats.dropped,
					  in.stats.waiting, in.stats.unpaired, in.skippedEntries, in.stats.captureFps,
					  in.disconnected ? "true" : "false", in.recorded, sum.typicalDepth);
		head += buf;
		head += ", \"device\": \"" + jsonEscape(in.device) + "\"},\n";
		head += "  \"rolling_shutter\": {\"readout_s\": " + formatNumber(sum.readout.seconds, 9) + ", \"source\": \"" +
				jsonEscape(sum.readout.source) + "\"},\n";
		if (const auto& m = sum.mapFiles; m.checkpointSeconds > 0)
			head += "  \"map_checkpoints\": {\"every_s\": " + formatNumber(m.checkpointSeconds) +
					", \"saved\": " + std::to_string(m.checkpoints) +
					", \"failed\": " + std::to_string(m.checkpointFailures) +
					", \"octrees_built\": " + std::to_string(m.checkpointOctrees) +
					", \"max_ms\": " + std::to_string(std::lround(m.checkpointMaxMs)) + ", \"last_error\": \"" +
					jsonEscape(m.checkpointError) + "\"},\n";
		return head + body.substr(body.find('\n') + 1);
	};
	// The small files first, so that a second Ctrl-C during the slow ones (the dense map's build,
	// the map file, the scene) never costs the trajectory or the statistics; each file is written
	// atomically, and after a second Ctrl-C the files not yet begun are skipped and stats.json says
	// which (issue 30: a second Ctrl-C used to leave only the two trajectories).
	// Every export in the run's world frame (z-up by default, issue 30), found once here.
	const TWorldFrame world = sys.worldFrame();
	const std::string frameNote = "\n" + world.describe();
	const TTrajectory trajectory = toWorldFrame(sys.trajectory(), world.worldFromMap);
	writeTumTrajectory((d / "trajectory.txt").string(), trajectory,
					   "camera pose (T_w_c) of every frame that has one: the pose tracking measured relative to its "
					   "reference keyframe, carried by that "
					   "keyframe's final pose (ORB-SLAM2's convention; no later frame used; lost frames as coasted)" +
						   frameNote);
	writeTumTrajectory((d / "trajectory_online.txt").string(), toWorldFrame(sys.onlineTrajectory(), world.worldFromMap),
					   "camera pose (T_w_c) of every frame that has one as the run had it then (tracked or coasted): "
					   "what a robot had" +
						   frameNote);
	const auto& out = sys.options().output;
	writeTumTrajectory(
		(d / "trajectory_smoothed.txt").string(), toWorldFrame(sys.smoothedTrajectory(), world.worldFromMap),
		"trajectory.txt smoothed after the run with up to " +
			std::to_string(std::max(out.correctionWindow, out.smoothingWindow)) +
			" LATER frames as well as earlier ones ([Output] correctionWindow " + std::to_string(out.correctionWindow) +
			", smoothingWindow " + std::to_string(out.smoothingWindow) + ", lostInterpolate " +
			(out.lostInterpolate ? "true" : "false") + "): not a pose a robot could have had" + frameNote);
	writeTumTrajectory((d / "keyframes.txt").string(), toWorldFrame(sys.keyFrameTrajectory(), world.worldFromMap),
					   "keyframe poses (T_w_c)" + frameNote);
	writeFileAtomically((d / "frames.csv").string(), formatFrameLogCsv(sys.frameLog()));
	if (sys.options().loop.detection.enabled)
		writeFileAtomically((d / "loop_candidates.csv").string(), formatLoopCandidatesCsv(sys.loopCandidates()));
	writeFileAtomically(
		(d / "config_used.ini").string(),
		"; the configuration of this run\n; [Tracking] rollingShutter = " + formatNumber(sum.readout.seconds, 9) +
			" s, from " + sum.readout.source + "\n" + sys.configUsed());
	writeFileAtomically((d / "stats.json").string(), statsJson(stop));
	sum.stats = sys.stats();

	std::vector<std::string> skipped;
	const auto go = [&](const std::string& what)
	{
		if (abort && abort())
		{
			skipped.push_back(what);
			return false;
		}
		return true;
	};
	std::optional<TDenseMap> dense;
	if (sys.denseMapper() && go("the dense map (dense_cloud.ply, map.ot, map.bt, map_2d.*)"))
	{
		// The dense map from the keyframes' final poses: labelled cloud, OctoMaps, and the octree in
		// the scene (coloured by label) so that yesslam-render pictures it.
		dense = sys.buildDenseMap();
		const TDenseMap& dm = *dense;
		const auto& names = sys.detector()->classNames();
		writeDenseCloudPly((d / "dense_cloud.ply").string(), dm.cloud, names, "dense semantic map", world.describe());
		writeSemanticOcTree((d / "map.ot").string(), *dm.octree);
		writeOccupancyBt((d / "map.bt").string(), *dm.octree);
		sum.dense.cloudPoints = dm.cloud.size();
		sum.dense.outliersRemoved = dm.outliersRemoved;
		sum.dense.buildMs = dm.buildMs;
		sum.dense.priorMerged = dm.priorMerged;
		for (auto it = dm.octree->begin_leafs(), end = dm.octree->end_leafs(); it != end; ++it)
			switch (dm.octree->stateOf(*it))
			{
				case EVoxelState::Occupied: sum.dense.occupiedLeaves++; break;
				case EVoxelState::Free: sum.dense.freeLeaves++; break;
				case EVoxelState::Unknown: sum.dense.unknownLeaves++; break;
			}
		writeGrid2D(sys, world, trajectory, dm, (d / "map_2d").string(), sum);
		std::error_code ec;
		sum.dense.plyBytes = fs::file_size(d / "dense_cloud.ply", ec);
		sum.dense.otBytes = fs::file_size(d / "map.ot", ec);
		sum.dense.btBytes = fs::file_size(d / "map.bt", ec);
	}
	if (!mapPath.empty() && go("the map file " + mapPath))
	{
		// With the semantic OctoMap of this run when there is one (yesslam-map exports it).
		try
		{
			sys.saveMap(mapPath, dense ? dense->octree.get() : nullptr);
			std::error_code ec;
			sum.mapFiles.savedBytes = fs::file_size(mapPath, ec);
		}
		catch (const std::exception& e)
		{
			sum.mapFiles.saveError = e.what();
		}
	}
	if (go("map.3Dscene"))
	{
		auto scene = buildMapScene(sys.map(), trajectory, world.worldFromMap);
		if (dense)
		{
			const auto& names = sys.detector()->classNames();
			scene->insert(semanticOcTreeObject(*dense->octree, names));
			// The dense cloud too, in its colours ("yesslam-render --hide octomap" shows it alone).
			auto cloud = mrpt::opengl::CPointCloudColoured::Create();
			cloud->setName("dense_cloud");
			cloud->setPointSize(2.0f);
			for (std::size_t i = 0; i < dense->cloud.size(); i++)
			{
				const auto& p = dense->cloud.xyz[i];
				const auto& c = dense->cloud.bgr[i];
				cloud->push_back(p.x, p.y, p.z, c[2] / 255.f, c[1] / 255.f, c[0] / 255.f);
			}
			scene->insert(cloud);
		}
		saveSceneAtomically(*scene, (d / "map.3Dscene").string());
	}
	if (!skipped.empty())
	{
		std::string list;
		for (const auto& k : skipped) list += (list.empty() ? "" : ", ") + k;
		sum.skippedOutputs = skipped;
		writeFileAtomically((d / "stats.json").string(),
							statsJson((stop.empty() ? std::string() : stop + "; ") +
									  "saving aborted by a second Ctrl-C: not written: " + list));
	}
}
}  // namespace mrpt_yesslam
