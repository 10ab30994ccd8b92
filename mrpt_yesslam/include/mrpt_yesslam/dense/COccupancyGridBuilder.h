#pragma once
// The 2D occupancy grid a robot's planner navigates on (issue 67): the semantic OctoMap's height
// band above the floor (the robot's body) projected down, with the people never an obstacle.
#include <mrpt/math/TPoint3D.h>

#include <cstdint>
#include <set>
#include <vector>

#include "mrpt_yesslam/dense/CSemanticOcTree.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** A grid in the z-up world frame: cell (i, j) covers x in [originX + i r, originX + (i + 1) r)
 * and y in [originY + j r, ...), stored row by row from the lowest y (ROS's OccupancyGrid order). */
struct TOccupancyGrid2D
{
	/** ROS's OccupancyGrid values. */
	static constexpr std::int8_t kUnknown = -1, kFree = 0, kOccupied = 100;

	double resolution = 0.05;         //!< m per cell
	double originX = 0, originY = 0;  //!< the lower left corner of cell (0, 0), m
	int width = 0, height = 0;        //!< cells along x and y
	std::vector<std::int8_t> cells;   //!< width * height values, cell (i, j) at j * width + i
	double floorZ = 0;                //!< world z of the floor the band is measured from
	double minZ = 0, maxZ = 0;        //!< the band, world z
	bool floorSeen = false;           //!< false: floorZ assumed from the first camera ([Grid2D] cameraHeight)

	std::int8_t at(int i, int j) const { return cells[static_cast<std::size_t>(j) * width + i]; }
	/** The cell holding (x, y); false outside the grid. */
	bool cellOf(double x, double y, int& i, int& j) const;
	/** Cells holding `value`. */
	std::size_t count(std::int8_t value) const;
};

/** Builds the grid from the semantic octree. A column of cells is occupied where a static occupied
 * voxel lies in the band, free where rays crossed the band there and no surface was seen in it,
 * unknown otherwise; voxels labelled with a dynamic class are never an obstacle. The camera's own
 * path is free (the robot carrying it was there; ROS costmaps clear their footprint so too) unless a
 * static surface was seen in the band there (a hand-held camera over a desk). */
class COccupancyGridBuilder
{
   public:
	/** Section [Grid2D]. */
	struct TOptions : public TTableOptions<TOptions>
	{
		bool enabled = true;            //!< write map_2d.* with the dense map (needs the z-up world frame)
		double resolution = 0.05;       //!< m per cell
		double minHeight = 0.15;        //!< m above the floor: the band's bottom (above the floor's own noise)
		double maxHeight = 1.5;         //!< m above the floor: the band's top (the robot's height)
		double footprintRadius = 0.15;  //!< m: the cells this near the camera's path are free unless occupied
		/** m: the first camera's height above the floor, used only when the run saw no floor. */
		double cameraHeight = 1.0;

		/** Every option once: key, member, range, help. */
		COptionTable table();
	};

	explicit COccupancyGridBuilder(const TOptions& o) : opts_(o) {}

	/** The grid of `tree` (world frame) with the floor at world z `floorZ` (`floorSeen` false: an
	 * assumption, reported in the grid); `dynamicLabels` are the octree labels never occupied (COCO
	 * class c is label c + 1); `path` the camera positions (world frame) of tracked frames, cleared
	 * as the footprint. Throws std::invalid_argument for a bad band or resolution, or a grid over
	 * 2^25 cells. */
	TOccupancyGrid2D build(const CSemanticOcTree& tree, const std::set<std::uint8_t>& dynamicLabels,
						   const std::vector<mrpt::math::TPoint3D>& path, double floorZ, bool floorSeen) const;

	const TOptions& options() const { return opts_; }

   private:
	TOptions opts_;
};
}  // namespace mrpt_yesslam
