#include "mrpt_yesslam/system/SlamExport.h"

#include <mrpt/opengl/CFrustum.h>
#include <mrpt/opengl/CPointCloud.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfLines.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace mrpt_yesslam
{
namespace
{
double percentile(std::vector<double> v, double q)
{
	if (v.empty()) return 0;
	std::sort(v.begin(), v.end());
	const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5));
	return v[i];
}
}  // namespace

mrpt::opengl::COpenGLScene::Ptr buildMapScene(const CSparseMap& map, const TTrajectory& traj,
											  const mrpt::poses::CPose3D& worldFromMap)
{
	auto scene = mrpt::opengl::COpenGLScene::Create();
	// More ambient light than MRPT's 0.2: the OctoMap's voxel faces turned from the light (walls
	// seen from behind the light) were nearly black (issue 43); now at least half their colour.
	auto& light = scene->getViewport()->lightParameters();
	light.ambient = mrpt::img::TColorf(0.55f, 0.55f, 0.55f, 1.0f);
	light.diffuse = mrpt::img::TColorf(0.6f, 0.6f, 0.6f, 1.0f);
	// Named, so that yesslam-render --hide can leave parts out.
	auto cloud = mrpt::opengl::CPointCloudColoured::Create();
	cloud->setName("map_points");
	cloud->setPointSize(3.0f);
	for (const auto& p : map.points())
	{
		const auto w = worldFromMap.composePoint(p.position);
		cloud->push_back(static_cast<float>(w.x), static_cast<float>(w.y), static_cast<float>(w.z), p.color[2] / 255.f,
						 p.color[1] / 255.f, p.color[0] / 255.f);
	}
	scene->insert(cloud);
	for (const auto& k : map.keyFramePoses())
	{
		if (k.bad) continue;
		const auto& kf = k.pose;
		// A small frustum per keyframe (near 0.02 m, far 0.12 m, the TUM field of view).
		auto fr = mrpt::opengl::CFrustum::Create(0.02f, 0.12f, 62.f, 48.f, 1.5f, true, false);
		fr->setName("keyframe");
		fr->setColor_u8(0, 90, 220);
		fr->setPose(worldFromMap + kf);
		scene->insert(fr);
	}
	auto path = mrpt::opengl::CSetOfLines::Create();
	path->setName("trajectory");
	path->setColor_u8(220, 30, 30);
	path->setLineWidth(2.0f);
	// The same path as close red dots of a few pixels: OpenGL core profiles (CFBORender's EGL
	// context among them) draw every line one pixel wide, which a picture of a room all but loses.
	auto dots = mrpt::opengl::CPointCloud::Create();
	dots->setName("trajectory_dots");
	dots->setColor_u8(220, 30, 30);
	dots->setPointSize(4.0f);
	double length = 0;
	for (std::size_t i = 1; i < traj.size(); i++)
		length += std::hypot(traj[i].tx - traj[i - 1].tx, traj[i].ty - traj[i - 1].ty, traj[i].tz - traj[i - 1].tz);
	const double step = std::max(0.003, length / 20000);
	for (std::size_t i = 1; i < traj.size(); i++)
	{
		const auto &a = traj[i - 1], &b = traj[i];
		path->appendLine(a.tx, a.ty, a.tz, b.tx, b.ty, b.tz);
		const double seg = std::hypot(b.tx - a.tx, b.ty - a.ty, b.tz - a.tz);
		const int n = std::max(1, static_cast<int>(std::ceil(seg / step)));
		for (int k = 0; k < n; k++)
		{
			const double s = static_cast<double>(k) / n;
			dots->insertPoint(static_cast<float>(a.tx + s * (b.tx - a.tx)),
							  static_cast<float>(a.ty + s * (b.ty - a.ty)),
							  static_cast<float>(a.tz + s * (b.tz - a.tz)));
		}
	}
	if (!path->empty())
	{
		scene->insert(path);
		scene->insert(dots);
	}
	return scene;
}

std::string formatStatsJson(const TSlamStats& s, const TStatsContext& ctx)
{
	std::ostringstream o;
	char buf[256];
	o << "{\n";
	o << "  \"frames\": " << s.frames << ",\n";
	o << "  \"tracked_frames\": " << s.trackedFrames << ",\n";
	std::snprintf(buf, sizeof(buf), "%.4f",
				  s.frames ? static_cast<double>(s.trackedFrames) / static_cast<double>(s.frames) : 0.0);
	o << "  \"tracking_rate\": " << buf << ",\n";
	o << "  \"lost_frames\": " << s.lostFrames << ",\n";
	o << "  \"relocalisations\": " << s.relocalisations << ",\n";
	o << "  \"refused_poses\": " << s.refusedPoses << ",\n";
	o << "  \"keyframes\": " << s.keyFrames << ",\n";
	o << "  \"forced_keyframes\": " << s.forcedKeyFrames << ",\n";
	o << "  \"culled_keyframes\": " << s.culledKeyFrames << ",\n";
	o << "  \"keyframes_in_map\": " << s.keyFramesInMap << ",\n";
	o << "  \"map_points\": " << s.mapPoints << ",\n";
	o << "  \"moving_points_erased\": " << s.movingPointsErased << ",\n";
	o << "  \"loop_closing\": " << (ctx.loopClosing ? "true" : "false") << ",\n";
	o << "  \"loops\": {\"queries\": " << s.loops.queries << ", \"detected\": " << s.loops.consistent
	  << ", \"accepted\": " << s.loops.accepted << ", \"rejected_by_geometry\": " << s.loops.rejectedGeometry
	  << ", \"corrections\": " << s.loopCorrections << ", \"largest_correction_m\": " << s.largestLoopCorrection()
	  << ", \"global_ba_runs\": " << s.globalBundleRuns << ", \"global_ba_applied\": " << s.globalBundleApplied
	  << ", \"global_ba_cancelled\": " << s.globalBundleCancelled << "},\n";
	// Each corrected loop: the pair and what the correction did (so a bad correction can be found).
	o << "  \"loop_corrections\": [";
	for (std::size_t i = 0; i < s.loopRecords.size(); i++)
	{
		const TLoopRecord& r = s.loopRecords[i];
		char rec[512];
		std::snprintf(rec, sizeof(rec),
					  "{\"current\": %zu, \"matched\": %zu, \"current_stamp\": %.6f, \"matched_stamp\": %.6f, "
					  "\"score\": %.4f, \"inliers\": %zu, \"group_keyframes\": %zu, \"fused\": %zu, "
					  "\"loop_links\": %zu, \"graph_keyframes\": %zu, \"graph_edges\": %zu, \"correction_m\": %.6f, "
					  "\"ms\": %.1f}",
					  r.current, r.matched, r.currentStamp, r.matchedStamp, r.score, r.ransacInliers,
					  r.correction.groupKeyFrames, r.correction.fused, r.correction.loopLinks,
					  r.correction.graphKeyFrames, r.correction.graphEdges, r.correction.correctionMetres, r.correctMs);
		o << (i ? ",\n    " : "\n    ") << rec;
	}
	o << (s.loopRecords.empty() ? "],\n" : "\n  ],\n");
	o << "  \"dense_map\": " << (ctx.denseMap ? "true" : "false") << ",\n";
	if (ctx.denseMap)
	{
		std::snprintf(buf, sizeof(buf), "%.2f", static_cast<double>(s.denseBytes) / 1e6);
		o << "  \"dense\": {\"keyframes\": " << s.denseKeyFrames << ", \"stored_points\": " << s.densePoints
		  << ", \"stored_mb\": " << buf << ", \"dropped_culled_clouds\": " << s.denseDroppedClouds << "},\n";
	}
	o << "  \"keyframe_policy\": \"" << ctx.keyFramePolicy << "\",\n";
	o << "  \"dynamic_filter\": " << (ctx.dynamicFilter ? "true" : "false") << ",\n";
	o << "  \"stages_ms\": {";
	bool first = true;
	for (const auto& [name, v] : s.stageMs)
	{
		std::snprintf(buf, sizeof(buf), "\"median\": %.3f, \"p95\": %.3f, \"count\": %zu", percentile(v, 0.5),
					  percentile(v, 0.95), v.size());
		o << (first ? "\n" : ",\n") << "    \"" << name << "\": {" << buf << "}";
		first = false;
	}
	o << "\n  }\n}\n";
	return o.str();
}
const char* poseSourceName(EPoseSource s)
{
	switch (s)
	{
		case EPoseSource::Tracked: return "tracked";
		case EPoseSource::Coasted: return "coasted";
		case EPoseSource::Interpolated: return "interpolated";
		case EPoseSource::None: break;
	}
	return "none";
}

std::string formatFrameLogCsv(const std::vector<TFrameLogRow>& rows, bool header)
{
	std::string out;
	if (header)
		out =
			"frame,timestamp,tracked,keyframe,relocalised,features,static_features,detections,inliers,keyframes_in_map,"
			"map_points,detect_ms,detect_wait_ms,mask_ms,orb_ms,track_ms,keyframe_ms,pose\n";
	out.reserve(out.size() + rows.size() * 96);
	char buf[320];
	for (const auto& r : rows)
	{
		std::snprintf(buf, sizeof(buf), "%zu,%.6f,%d,%d,%d,%zu,%zu,%zu,%zu,%zu,%zu,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%s\n",
					  r.frame, r.timestamp, r.tracked ? 1 : 0, r.keyFrame ? 1 : 0, r.relocalised ? 1 : 0, r.features,
					  r.staticFeatures, r.detections, r.inliers, r.keyFramesInMap, r.mapPoints, r.detectMs,
					  r.detectWaitMs, r.maskMs, r.orbMs, r.trackMs, r.keyFrameMs, poseSourceName(r.pose));
		out += buf;
	}
	return out;
}

std::string formatLoopCandidatesCsv(const std::vector<TLoopCandidate>& candidates)
{
	std::string out =
		"query,query_stamp,candidate,candidate_stamp,bow_score,loop_score,min_score,stage,matches,inliers\n";
	char buf[256];
	for (const auto& c : candidates)
	{
		std::snprintf(buf, sizeof(buf), "%zu,%.6f,%zu,%.6f,%.5f,%.5f,%.5f,%s,%zu,%zu\n", c.query, c.queryStamp,
					  c.candidate, c.candidateStamp, c.bowScore, c.loopScore, c.minScore, c.stage, c.matches,
					  c.inliers);
		out += buf;
	}
	return out;
}
}  // namespace mrpt_yesslam
