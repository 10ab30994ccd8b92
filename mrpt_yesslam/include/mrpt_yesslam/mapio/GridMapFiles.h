#pragma once
// The 2D occupancy grid's files (issue 67): MRPT's COccupancyGridMap2D (.gridmap), ROS map_server's
// image and description (.pgm + .yaml), and a picture with the camera's path (.png).
#include <mrpt/math/TPoint3D.h>

#include <string>
#include <vector>

#include "mrpt_yesslam/dense/COccupancyGridBuilder.h"

namespace mrpt_yesslam
{
/** The grid as an mrpt::maps::COccupancyGridMap2D (occupied cells at probability of being free 0,
 * free 1, unknown 0.5), serialized as MRPT's CSerializable (read it with
 * mrpt::serialization::archiveFrom(CFileGZInputStream(path)) >> grid); atomically. */
void writeMrptGridMap(const std::string& path, const TOccupancyGrid2D& grid);

/** ROS map_server's map: `pgmPath` (P5, map_saver's values: occupied 0, free 254, unknown 205, the
 * first row the largest y) and `yamlPath` naming it by file name (resolution, origin, negate 0,
 * occupied_thresh 0.65, free_thresh 0.196); both atomically. */
void writeRosMap(const std::string& yamlPath, const std::string& pgmPath, const TOccupancyGrid2D& grid);

/** Reads a map written by writeRosMap (or any trinary map_server map with negate 0) back into a
 * grid; throws InputError naming the file for anything else. */
TOccupancyGrid2D readRosMap(const std::string& yamlPath);

/** The grid as a picture (occupied black, free white, unknown grey, a few pixels a cell) with the
 * camera's `path` in red from a green start, the first row the largest y; atomically. */
void writeGridPng(const std::string& path, const TOccupancyGrid2D& grid,
				  const std::vector<mrpt::math::TPoint3D>& path3d);

/** The four files `base`.gridmap, .pgm, .yaml and .png. */
void writeGridMapFiles(const std::string& base, const TOccupancyGrid2D& grid,
					   const std::vector<mrpt::math::TPoint3D>& path);
}  // namespace mrpt_yesslam
