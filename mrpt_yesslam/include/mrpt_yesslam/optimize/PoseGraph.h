#pragma once
// Pose-graph optimisation in Ceres (ORB-SLAM2's OptimizeEssentialGraph, with SE3 instead of Sim3:
// RGB-D measures scale). Each edge holds the relative pose measured between two keyframes; the
// optimiser moves the keyframes so that all edges agree as well as possible, which spreads the
// error a loop reveals along the whole loop instead of leaving it at the place it closed.
#include <mrpt/poses/CPose3D.h>

#include <map>
#include <set>
#include <vector>

#include "mrpt_yesslam/data/CMapPoint.h"

namespace mrpt_yesslam
{
/** A relative-pose constraint: T_a^-1 T_b measured = `relative` (camera b in camera a's frame). */
struct TPoseGraphEdge
{
	TKeyFrameId a = 0, b = 0;
	mrpt::poses::CPose3D relative;
	double weight = 1;  //!< scales the residual (ORB-SLAM2: identity information for every edge)
};

/** Optimises the poses (T_w_c) of the vertices; `fixed` vertices keep theirs. Returns the
 * optimised poses of every vertex. */
std::map<TKeyFrameId, mrpt::poses::CPose3D> optimisePoseGraph(
	const std::map<TKeyFrameId, mrpt::poses::CPose3D>& initial, const std::vector<TPoseGraphEdge>& edges,
	const std::set<TKeyFrameId>& fixed, int iterations = 20, double* finalCost = nullptr);
}  // namespace mrpt_yesslam
