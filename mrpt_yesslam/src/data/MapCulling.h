#pragma once
// Culling rules of the sparse map (ORB-SLAM2's MapPointCulling and KeyFrameCulling, and the
// see-through rule for points that moved away): which recent points and which redundant
// keyframes go. Private to the library; the caller holds the map's lock (CSparseMap does).
#include "SparseMapStore.h"

namespace mrpt_yesslam::sparse_map
{
/** See CSparseMap::countTracking. */
std::size_t countTracking(TSparseMapStore& s, const std::vector<TPointId>& visible, const std::vector<TPointId>& found,
						  const std::vector<TPointId>& seenThrough, int seeThroughFrames);
/** See CSparseMap::cullRecentPoints. */
std::size_t cullRecentPoints(TSparseMapStore& s, TKeyFrameId currentKf, double minFoundRatio,
							 std::size_t minObservations);
/** See CSparseMap::cullRedundantKeyFrames. */
std::vector<TKeyFrameId> cullRedundantKeyFrames(TSparseMapStore& s, TKeyFrameId currentKf, double redundantRatio,
												std::size_t minOtherObservers, double maxDepth);
}  // namespace mrpt_yesslam::sparse_map
