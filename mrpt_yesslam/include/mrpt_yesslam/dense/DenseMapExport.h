#pragma once
// Files and scene objects of the dense semantic map: dense_cloud.ply, map.ot, map.bt, and the
// octree as MRPT voxels (coloured by label, with a legend) for map.3Dscene / yesslam-render.
#include <mrpt/opengl/CSetOfObjects.h>

#include <string>
#include <vector>

#include "mrpt_yesslam/dense/CDenseSemanticMapper.h"

namespace mrpt_yesslam
{
/** Writes the cloud as binary little-endian PLY (x y z float, red green blue uchar, label uchar,
 * label_prob float, observations uint), with one "comment label N name" line per label present;
 * atomically. `names[c]` names class c (label c + 1); `what` says in the header what the points
 * are, `frame` the frame they are in (TWorldFrame::describe(); one comment line per line). */
void writeDenseCloudPly(const std::string& path, const TDenseCloud& cloud, const std::vector<std::string>& names,
						const std::string& what, const std::string& frame);

/** Reads a PLY written by writeDenseCloudPly (tests, tools); throws InputError naming the file. */
TDenseCloud readDenseCloudPly(const std::string& path);

/** Writes the octree as .ot (OctoMap's full format: occupancy, colour, label) atomically. */
void writeSemanticOcTree(const std::string& path, const CSemanticOcTree& tree);
/** Writes the occupancy alone as .bt (OctoMap's binary OcTree: octovis, octomap_server), atomically;
 * returns the leaves the file holds (unknown voxels are left out, uniform subtrees are one leaf). */
std::size_t writeOccupancyBt(const std::string& path, const CSemanticOcTree& tree);

/** The occupied leaves as MRPT voxels coloured by label (or by colour with `byLabel` false), with
 * the legend of the labels present as a hidden set "legend" of coloured texts (yesslam-render
 * draws it over the picture); named "octomap". */
mrpt::opengl::CSetOfObjects::Ptr semanticOcTreeObject(const CSemanticOcTree& tree,
													  const std::vector<std::string>& names, bool byLabel = true);

/** "name" of a label: "background" for 0, names[label - 1], or "class N". */
std::string labelName(TSemLabel label, const std::vector<std::string>& names);
}  // namespace mrpt_yesslam
