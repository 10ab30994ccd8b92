#pragma once
// What yesslam-map shows and exports of a saved map: its size, extent, time span and the classes
// its keyframes saw, and the map as a scene, a point cloud or an occupancy octree.
#include <memory>
#include <string>
#include <vector>

#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/dense/CDenseSemanticMapper.h"
#include "mrpt_yesslam/dense/CSemanticOcTree.h"

namespace mrpt_yesslam
{
/** A map in figures. */
struct TMapSummary
{
	std::size_t keyFrames = 0, erasedKeyFrames = 0, points = 0, loopEdges = 0;
	double firstTime = 0, lastTime = 0;  //!< keyframe timestamps, seconds
	mrpt::math::TPoint3D min, max;       //!< bounding box of the points (world frame, metres)
	double pathLength = 0;               //!< keyframe to keyframe, in time order (metres)
	/** Per detected class (by name): keyframes that saw it, most seen first. */
	std::vector<std::pair<std::string, std::size_t>> classes;
};

/** Figures of `map`; `classNames[c]` names class c (others are "class c"); the extent in the
 * frame `worldFromMap` places the map in (the map file's TWorldFrame). */
TMapSummary summarizeMap(const CSparseMap& map, const std::vector<std::string>& classNames,
						 const mrpt::poses::CPose3D& worldFromMap = mrpt::poses::CPose3D());
/** The summary as "key: value" lines (yesslam-map's output). */
std::string formatMapSummary(const TMapSummary& s);
/** The good points as a cloud (colour; label 0, observations = keyframes seeing each), for
 * writeDenseCloudPly, placed by `worldFromMap` (the map file's TWorldFrame). */
TDenseCloud mapPointCloud(const CSparseMap& map, const mrpt::poses::CPose3D& worldFromMap = mrpt::poses::CPose3D());
/** Occupancy from the map: each good keyframe's points inserted as a scan from its camera centre
 * (the space in front of them free, their voxels occupied), at `resolution` metres, placed by
 * `worldFromMap`. */
std::unique_ptr<CSemanticOcTree> mapOccupancy(const CSparseMap& map, double resolution,
											  const mrpt::poses::CPose3D& worldFromMap = mrpt::poses::CPose3D());
}  // namespace mrpt_yesslam
