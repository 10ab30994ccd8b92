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

	std::uint8_t r = 255, g = 255, b = 255;	 //!< mean colour of what was seen there
	std::uint8_t label = 0;	 //!< fused label
	float labelProb = 0;  //!< its probability after fusion (0 = never labelled)
};

/** The octree (see the file comment). */
class CSemanticOcTree : public octomap::OccupancyOcTreeBase<CSemanticOcTreeNode>
{
   public:
	explicit CSemanticOcTree(double resolution);
	CSemanticOcTree(const CSemanticOcTree&) = delete;  //!< see CSemanticOcTreeNode's copy constructor
	CSemanticOcTree& operator=(const CSemanticOcTree&) = delete;
	/** OctoMap's factory needs it (reading .ot files). */
	CSemanticOcTree* create() const override { return new CSemanticOcTree(resolution); }
	std::string getTreeType() const override { return "YesSlamSemanticOcTree"; }

	/** Gives every inner node the colour and label of its occupied children (mean colour; the
	 * label with the largest summed probability, and that sum over the occupied children as its
	 * probability), so that a viewer showing a coarser level (octovis' depth slider, a client
	 * asking for a lower resolution) sees them too; occupancy as updateInnerOccupancy (the
	 * largest child's). Call after the leaves are set, before prune() (as ColorOcTree's
	 * updateInnerOccupancy does for its colours). */
	void updateInnerSemantics();

	/** Reads a .ot file written by write(); throws InputError naming `path` when it is missing,
	 * corrupt, truncated or holds another tree type. */
	static std::unique_ptr<CSemanticOcTree> readFile(const std::string& path);
	/** The same from a stream holding exactly one .ot (saved maps embed one); `name` is used in
	 * error messages. */
	static std::unique_ptr<CSemanticOcTree> read(std::istream& in, const std::string& name);

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
