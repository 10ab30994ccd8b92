#pragma once
// The semantic OctoMap: an occupancy octree (OctoMap's log-odds update, ray-cast free space) whose
// nodes also carry a colour and the fused class label with its probability.
//
// Chosen over ColorOcTree + a label side file: one self-describing .ot file that any program
// linking this library reads with OctoMap's own AbstractOcTree::read (the tree type registers
// itself as "YesSlamSemanticOcTree"), and labels that cannot get out of step with the voxels.
// Tools that know only OctoMap's own types (octovis, ROS's octomap_server) read the .bt we write
// beside it (occupancy only). Measured cost over ColorOcTree: 5 bytes per node in memory and in
// the .ot (value 4 + colour 3 + label 1 + probability 4 = 12 bytes per node).
#include <octomap/OccupancyOcTreeBase.h>
#include <octomap/OcTreeNode.h>

#include <cstdint>
#include <memory>
#include <string>

namespace mrpt_yesslam
{
/** A node: occupancy log-odds, colour, label (0 = background, c + 1 = COCO class c) and its
 * fused probability. */
class CSemanticOcTreeNode : public octomap::OcTreeNode
{
   public:
	CSemanticOcTreeNode() = default;
	/** Deleted: OctoMap's node copy constructor copies the children as its own base node type
	 * (sliced: their colour and label read past the allocation), and a node's children belong to
	 * its tree, which deletes them. Trees are not copied either (their copy is deleted too);
	 * copyData copies a node's own data. */
	CSemanticOcTreeNode(const CSemanticOcTreeNode& o) = delete;
	CSemanticOcTreeNode& operator=(const CSemanticOcTreeNode&) = delete;

	/** Equal occupancy, colour, label and label probability: the octree prunes only children
	 * equal in all of them, so that pruning never merges two different beliefs into one. */
	bool operator==(const CSemanticOcTreeNode& o) const
	{
		return o.value == value && o.r == r && o.g == g && o.b == b && o.label == label && o.labelProb == labelProb;
	}
	/** Copies occupancy and semantics (OctoMap's pruning and expansion use it). */
	void copyData(const CSemanticOcTreeNode& from)
	{
		octomap::OcTreeNode::copyData(from);
		r = from.r, g = from.g, b = from.b, label = from.label, labelProb = from.labelProb;
	}
	/** The node's record in a .ot file. */
	std::istream& readData(std::istream& s);
	std::ostream& writeData(std::ostream& s) const;

	std::uint8_t r = 255, g = 255, b = 255;  //!< mean colour of what was seen there
	std::uint8_t label = 0;                  //!< fused label
	float labelProb = 0;                     //!< its probability after fusion (0 = never labelled)
};

/** What a voxel's evidence says, as every export tells it (.bt, the summaries, yesslam-map). */
enum class EVoxelState : std::uint8_t
{
	Free,     //!< rays passed through it and no surface was ever measured there
	Unknown,  //!< a surface was measured there, but too few keyframes confirm it (or later rays contradict it)
	Occupied  //!< at or above the occupancy threshold
};

/** The octree (see the file comment).
 *
 * Issue 43: a voxel where any scan ended (a measured surface) is never free afterwards. OctoMap's
 * log-odds alone cannot say so: one hit (+0.85 at probHit 0.7) below the 0.8 threshold was written
 * to .bt as free, as was a wall voxel that later rays grazed (each miss -0.41). So a voxel's
 * log-odds never goes to or below 0 once it has been hit (it stays at kSeenLogOdds at least): the
 * sign of the stored value tells whether a surface was ever seen there, in memory, in .ot files
 * and in saved maps, with no change to their format. Values <= 0 are voxels only rays passed. */
class CSemanticOcTree : public octomap::OccupancyOcTreeBase<CSemanticOcTreeNode>
{
   public:
	/** The least log-odds of a voxel that has been hit (probability 0.51): unknown, not free. */
	static constexpr float kSeenLogOdds = 0.04f;

	explicit CSemanticOcTree(double resolution);
	CSemanticOcTree(const CSemanticOcTree&) = delete;  //!< see CSemanticOcTreeNode's copy constructor
	CSemanticOcTree& operator=(const CSemanticOcTree&) = delete;
	/** OctoMap's factory needs it (reading .ot files). */
	CSemanticOcTree* create() const override { return new CSemanticOcTree(resolution); }
	std::string getTreeType() const override { return "YesSlamSemanticOcTree"; }

	/** Free, unknown or occupied (see EVoxelState): occupied at the occupancy threshold, free only
	 * where no surface was ever measured. */
	EVoxelState stateOf(const CSemanticOcTreeNode& n) const
	{
		if (isNodeOccupied(n)) return EVoxelState::Occupied;
		return n.getLogOdds() > 0 ? EVoxelState::Unknown : EVoxelState::Free;
	}

	/** Gives every inner node the colour and label of its occupied children (mean colour; the
	 * label with the largest summed probability, and that sum over the occupied children as its
	 * probability), so that a viewer showing a coarser level (octovis' depth slider, a client
	 * asking for a lower resolution) sees them too; occupancy as updateInnerOccupancy (the
	 * largest child's). Call after the leaves are set, before prune() (as ColorOcTree's
	 * updateInnerOccupancy does for its colours). */
	void updateInnerSemantics();

	/** Inserts one scan taken from `origin`: the cells of its points are hit once each (OctoMap's
	 * discretised insertPointCloud), and the cells its rays pass are missed - but only up to
	 * `clearMargin` metres before each point. Each point stands for the surface within
	 * `pointSpacing` of it (a thinned cloud keeps one point of each cell): the cells that reach
	 * are not missed and become at least unknown (kSeenLogOdds), never free. Space within the depth
	 * noise and the thinning of a measured surface is no evidence of free space: cleared right up
	 * to the kept points, voxels holding the surface seen by the other pixels were free (issue 43). */
	void insertScan(const octomap::Pointcloud& scan, const octomap::point3d& origin, double clearMargin,
					double pointSpacing = 0);

	/** The tree as .ot bytes: OctoMap's format, with the occupancy threshold in a header comment
	 * ("# yesslam occupancy_threshold P") that read() takes back (OctoMap's readers skip it). */
	std::string otBytes() const;

	/** Reads a .ot file written by write(); throws InputError naming `path` when it is missing,
	 * corrupt, truncated or holds another tree type. */
	static std::unique_ptr<CSemanticOcTree> readFile(const std::string& path);
	/** The same from a stream holding exactly one .ot (saved maps embed one); `name` is used in
	 * error messages. */
	static std::unique_ptr<CSemanticOcTree> read(std::istream& in, const std::string& name);

   protected:
	/** OctoMap's update (add, clamp), except that a voxel ever hit keeps at least kSeenLogOdds:
	 * every update path of the tree (scans, rays, single nodes) goes through it. */
	void updateNodeLogOdds(CSemanticOcTreeNode* node, const float& update) const override;

   private:
	/** updateInnerSemantics below `node` (at `depth`). */
	void updateInnerSemanticsRecurs(CSemanticOcTreeNode* node, unsigned depth);
	/** Registers the type with OctoMap's factory once (as OctoMap's own trees do). */
	struct TRegistration
	{
		TRegistration();
		void ensureLinking() {}
	};
	static TRegistration registration_;
};
}  // namespace mrpt_yesslam
