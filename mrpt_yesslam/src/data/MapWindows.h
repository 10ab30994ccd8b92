#pragma once
// Which keyframes and points a stage works on, chosen from the covisibility graph and copied out:
// tracking's local keyframes (ORB-SLAM2's UpdateLocalKeyFrames), local and global bundle
// adjustment windows, and the write-back of their results, refused when a correction landed in
// between. Private to the library; the caller holds the map's lock (CSparseMap does).
#include "SparseMapStore.h"

namespace mrpt_yesslam::sparse_map
{
/** See CSparseMap::localKeyFrames. */
std::vector<TKeyFrameId> localKeyFrames(const TSparseMapStore& s, const std::vector<TPointId>& seeds,
										TKeyFrameId fallback, std::size_t maxKeyFrames, std::size_t neighbours);
/** See CSparseMap::bundleWindow. */
TBundleWindow bundleWindow(const TSparseMapStore& s, TKeyFrameId id, std::size_t numCovisible, std::size_t maxFixed);
/** See CSparseMap::globalBundleWindow. */
TBundleWindow globalBundleWindow(const TSparseMapStore& s);
/** See CSparseMap::applyBundle. */
bool applyBundle(TSparseMapStore& s, const TBundleWindow& w, const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses,
				 const std::vector<mrpt::math::TPoint3D>& positions,
				 const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers);
/** See CSparseMap::applyGlobalBundle. */
bool applyGlobalBundle(TSparseMapStore& s, const TBundleWindow& w,
					   const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses,
					   const std::vector<mrpt::math::TPoint3D>& positions,
					   const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers);
}  // namespace mrpt_yesslam::sparse_map
