#pragma once
// What a SLAM run exports besides its trajectories: the sparse map as an MRPT scene and the run's
// figures as stats.json. Outside the system, which stays a facade over its stages, so that tools
// and map saving can export a map without a running system.
#include <mrpt/opengl/COpenGLScene.h>

#include <string>

#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/system/TSlamStats.h"

namespace mrpt_yesslam
{
/** Coloured map points, a frustum per keyframe and the trajectory, for SceneViewer3D and
 * yesslam-render; the objects are named (map_points, keyframe, trajectory) for --hide. The map is
 * placed by `worldFromMap` (TWorldFrame); `trajectory` is already in that frame. */
mrpt::opengl::COpenGLScene::Ptr buildMapScene(const CSparseMap& map, const TTrajectory& trajectory,
											  const mrpt::poses::CPose3D& worldFromMap = mrpt::poses::CPose3D());

/** How a run was configured, as stats.json states it beside the figures. */
struct TStatsContext
{
	bool loopClosing = true, denseMap = false, dynamicFilter = true;
	std::string keyFramePolicy;
};

/** The figures of a run as JSON (per-stage median and p95 in ms). */
std::string formatStatsJson(const TSlamStats& stats, const TStatsContext& context);
/** frames.csv: a header line (unless `header` is false), then one line per processed frame (TFrameLogRow). */
std::string formatFrameLogCsv(const std::vector<TFrameLogRow>& rows, bool header = true);
/** loop_candidates.csv: a header line, then every loop candidate (TLoopCandidate) in order. */
std::string formatLoopCandidatesCsv(const std::vector<TLoopCandidate>& candidates);
}  // namespace mrpt_yesslam
