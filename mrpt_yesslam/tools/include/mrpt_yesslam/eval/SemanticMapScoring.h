#pragma once
// Scores a semantic octree against a yesslam-sim sequence's exact labels: which voxels the people
// swept through (and whether any is left occupied: a "ghost"), and whether occupied voxels carry
// the class of the static object there. For bench/bench_dense.sh and the dense-map tests.
#include <mrpt/poses/CPose3D.h>

#include <map>
#include <string>

#include "mrpt_yesslam/dense/COccupancyGridBuilder.h"
#include "mrpt_yesslam/dense/CSemanticOcTree.h"

namespace mrpt_yesslam
{
/** The scores. Voxels are the octree's leaves at its resolution. */
struct TSemanticMapScore
{
	std::size_t sweptVoxels = 0;    //!< voxels a moving object's surface passed through, away from static surfaces
	std::size_t ghostVoxels = 0;    //!< of those, occupied in the map (goal: 0)
	std::size_t scoredVoxels = 0;   //!< occupied map voxels on a static surface of the ground truth
	std::size_t labelCorrect = 0;   //!< of those, carrying the ground truth's majority label (background included)
	std::size_t objectVoxels = 0;   //!< scored voxels whose ground truth is an object (not background)
	std::size_t objectCorrect = 0;  //!< of those, labelled with that object's class
	std::size_t labelledObjectVoxels = 0;   //!< scored voxels the map labels as an object
	std::size_t labelledObjectCorrect = 0;  //!< of those, right
	/** Per ground-truth label: (correct, scored). */
	std::map<int, std::pair<std::size_t, std::size_t>> perLabel;

	double ghostShare() const { return sweptVoxels ? double(ghostVoxels) / double(sweptVoxels) : 0.0; }
	double labelAccuracy() const { return scoredVoxels ? double(labelCorrect) / double(scoredVoxels) : 0.0; }
	double objectRecall() const { return objectVoxels ? double(objectCorrect) / double(objectVoxels) : 0.0; }
	double objectPrecision() const
	{
		return labelledObjectVoxels ? double(labelledObjectCorrect) / double(labelledObjectVoxels) : 0.0;
	}
};

/** Back-projects every `frameStep`-th frame of the yesslam-sim folder `simDir` (depth, labels/,
 * objects.txt, groundtruth.txt) at every `pixelStep`-th pixel into the map's frame, with
 * `mapInGt` = the pose of the map's world frame in the ground-truth world (the first keyframe's
 * ground-truth pose times the inverse of its estimated pose), and scores `tree`. A swept voxel
 * next to (26-neighbourhood) a static surface voxel is not counted (a person touching a desk).
 * Throws InputError for a folder that is not a yesslam-sim output, or whose depth images were not
 * taken with their colour images (--depth-offset: the labels are the colour image's). */
TSemanticMapScore scoreSemanticMap(const CSemanticOcTree& tree, const std::string& simDir,
								   const mrpt::poses::CPose3D& mapInGt, int frameStep = 3, int pixelStep = 4);

/** How a 2D grid (COccupancyGridBuilder) agrees with a yesslam-sim sequence (issue 67). Cells are
 * the grid's; "in the band" is the grid's band. */
struct TGridScore
{
	std::size_t pathCells = 0;         //!< cells under the camera's true path
	std::size_t pathFree = 0;          //!< of those, free
	std::size_t pathCellsOutside = 0;  //!< true camera positions outside the grid
	std::size_t staticCells = 0;       //!< cells holding a static surface in the band
	std::size_t staticOccupied = 0;    //!< of those, occupied within one cell
	std::size_t sweptCells = 0;        //!< cells only moving objects passed in the band (none static within one cell)
	std::size_t sweptOccupied = 0;     //!< of those, occupied (goal: none)

	double pathFreeShare() const { return pathCells ? double(pathFree) / double(pathCells) : 0.0; }
	double staticOccupiedShare() const { return staticCells ? double(staticOccupied) / double(staticCells) : 0.0; }
	double sweptOccupiedShare() const { return sweptCells ? double(sweptOccupied) / double(sweptCells) : 0.0; }
};

/** Scores `grid` against the yesslam-sim folder `simDir` (every frame's true camera position;
 * the surfaces of every `frameStep`-th frame at every `pixelStep`-th pixel), with `mapInGt` as
 * for scoreSemanticMap (the grid's world frame in the ground truth's). */
TGridScore scoreGrid2D(const TOccupancyGrid2D& grid, const std::string& simDir, const mrpt::poses::CPose3D& mapInGt,
					   int frameStep = 3, int pixelStep = 4);
}  // namespace mrpt_yesslam
