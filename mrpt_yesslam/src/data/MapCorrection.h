#pragma once
// The loop-closing side of the map: loop edges, ORB-SLAM2's essential graph, and the maths of a
// correction (each keyframe's T_new T_old^-1 carried to what moves with it, every point moved
// exactly once). Private to the library; the caller holds the map's lock (CSparseMap does).
#include <set>

#include "SparseMapStore.h"

namespace mrpt_yesslam::sparse_map
{
/** See CSparseMap::addLoopEdge. */
bool addLoopEdge(TSparseMapStore& s, TKeyFrameId a, TKeyFrameId b);
/** See CSparseMap::essentialGraph. */
std::vector<std::pair<TKeyFrameId, TKeyFrameId>> essentialGraph(const TSparseMapStore& s, int minWeight);
/** Sets keyframe poses and moves points (see CSparseMap::applyCorrection); `propagate` false: only
 * the listed keyframes move, and the points they observe (CSparseMap::correctKeyFrames). Points in
 * `skip` keep their position. Starts a new correction generation. */
void correct(TSparseMapStore& s, const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses, bool propagate,
			 const std::set<TPointId>& skip = {});
}  // namespace mrpt_yesslam::sparse_map
