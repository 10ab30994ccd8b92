#include "mrpt_yesslam/dense/DenseMapExport.h"

#include <mrpt/opengl/COctoMapVoxels.h>
#include <mrpt/opengl/CText.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
std::string labelName(TSemLabel label, const std::vector<std::string>& names)
{
	if (label == 0) return "background";
	if (label - 1u < names.size()) return names[label - 1u];
	return "class " + std::to_string(label - 1);
}

namespace
{
constexpr std::size_t kPlyRecord = 3 * 4 + 3 + 1 + 4 + 4;

template <class T>
void put(std::string& s, const T& v)
{
	s.append(reinterpret_cast<const char*>(&v), sizeof(T));
}
}  // namespace

void writeDenseCloudPly(const std::string& path, const TDenseCloud& c, const std::vector<std::string>& names,
						const std::string& what, const std::string& frame)
{
	std::ostringstream h;
	h << "ply\nformat binary_little_endian 1.0\ncomment mrpt_yesslam " << what << "\n";
	std::istringstream lines(frame);
	for (std::string line; std::getline(lines, line);)
		if (!line.empty()) h << "comment " << line << "\n";
	std::map<TSemLabel, std::size_t> present;
	for (const auto l : c.label) present[l]++;
	for (const auto& [l, n] : present) h << "comment label " << int(l) << " " << labelName(l, names) << "\n";
	h << "element vertex " << c.size() << "\n"
	  << "property float x\nproperty float y\nproperty float z\n"
	  << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
	  << "property uchar label\nproperty float label_prob\nproperty uint observations\nend_header\n";
	std::string s = h.str();
	s.reserve(s.size() + c.size() * kPlyRecord);
	static_assert(sizeof(float) == 4, "PLY floats are 4 bytes");
	for (std::size_t i = 0; i < c.size(); i++)
	{
		put(s, c.xyz[i].x), put(s, c.xyz[i].y), put(s, c.xyz[i].z);
		put(s, c.bgr[i][2]), put(s, c.bgr[i][1]), put(s, c.bgr[i][0]);
		put(s, c.label[i]), put(s, c.labelProb[i]), put(s, c.observations[i]);
	}
	writeFileAtomically(path, s);
}

TDenseCloud readDenseCloudPly(const std::string& path)
{
	std::ifstream in(path, std::ios::binary);
	if (!in) throw InputError(path, "cannot open");
	std::string line;
	std::size_t n = 0;
	bool ours = false, formatOk = false;
	std::getline(in, line);
	if (line != "ply") throw InputError(path, "not a PLY file");
	while (std::getline(in, line) && line != "end_header")
	{
		if (line.rfind("format binary_little_endian 1.0", 0) == 0) formatOk = true;
		if (line.rfind("comment mrpt_yesslam ", 0) == 0) ours = true;
		if (line.rfind("element vertex ", 0) == 0) n = std::stoul(line.substr(15));
	}
	if (line != "end_header" || !formatOk || !ours) throw InputError(path, "not a dense_cloud.ply written by yesslam");
	const std::streamoff start = in.tellg();
	in.seekg(0, std::ios::end);
	if (in.tellg() - start != static_cast<std::streamoff>(n * kPlyRecord))
		throw InputError(path, "truncated or corrupt: " + std::to_string(n) + " points announced");
	in.seekg(start);
	std::string data(n * kPlyRecord, '\0');
	in.read(data.data(), static_cast<std::streamsize>(data.size()));
	TDenseCloud c;
	const char* p = data.data();
	auto get = [&](auto& v)
	{
		std::memcpy(&v, p, sizeof(v));
		p += sizeof(v);
	};
	for (std::size_t i = 0; i < n; i++)
	{
		cv::Point3f x;
		cv::Vec3b col;
		TSemLabel l;
		float pr;
		std::uint32_t o;
		get(x.x), get(x.y), get(x.z), get(col[2]), get(col[1]), get(col[0]), get(l), get(pr), get(o);
		c.xyz.push_back(x), c.bgr.push_back(col), c.label.push_back(l), c.labelProb.push_back(pr),
			c.observations.push_back(o);
	}
	return c;
}

void writeSemanticOcTree(const std::string& path, const CSemanticOcTree& tree)
{
	writeFileAtomically(path, tree.otBytes());
}

namespace
{
// One subtree in OctoMap's binary (.bt) encoding: per node two bytes of 2-bit child codes (01
// occupied leaf, 10 free leaf, 11 inner node, 00 unknown: no node), then the inner children's
// subtrees in order, depth first. The encoding of `node` as a child: its code, and for an inner
// node its bytes and node count.
struct TBtSubtree
{
	unsigned code = 0;  //!< 0 unknown, 1 occupied, 2 free, 3 inner
	std::string bytes;
	std::size_t nodes = 0;   //!< nodes below it that OctoMap's reader creates
	std::size_t leaves = 0;  //!< of those, leaves (occupied or free)
};

constexpr unsigned kBtUnknown = 0, kBtOccupied = 1, kBtFree = 2, kBtInner = 3;

unsigned btLeafCode(const CSemanticOcTree& tree, const CSemanticOcTreeNode& n)
{
	switch (tree.stateOf(n))
	{
		case EVoxelState::Occupied: return kBtOccupied;
		case EVoxelState::Free: return kBtFree;
		default: return kBtUnknown;
	}
}

// The children of `node` (a leaf node stands for eight children like itself: the root of a tree
// pruned to one leaf).
TBtSubtree btChildren(const CSemanticOcTree& tree, const CSemanticOcTreeNode& node)
{
	std::array<TBtSubtree, 8> child;
	for (unsigned i = 0; i < 8; i++)
	{
		if (!tree.nodeHasChildren(&node))
			child[i].code = btLeafCode(tree, node);
		else if (tree.nodeChildExists(&node, i))
		{
			const CSemanticOcTreeNode& c = *tree.getNodeChild(&node, i);
			if (tree.nodeHasChildren(&c))
				child[i] = btChildren(tree, c);
			else
				child[i].code = btLeafCode(tree, c);
		}
	}
	TBtSubtree out;
	// Eight occupied or eight free children are one leaf; all unknown is no node.
	const bool same = std::all_of(child.begin(), child.end(),
								  [&](const TBtSubtree& c) { return c.code == child[0].code && c.code != kBtInner; });
	if (same)
	{
		out.code = child[0].code;
		return out;
	}
	std::uint8_t bits[2] = {0, 0};
	for (unsigned i = 0; i < 8; i++)
	{
		// OctoMap's bit order: child i's code in bits 2i (low) and 2i+1 (high) of its byte, with
		// code 01 = bit 2i+1 only (occupied), 10 = bit 2i only (free).
		const unsigned c = child[i].code, j = (i % 4) * 2;
		if (c == kBtOccupied) bits[i / 4] |= 1u << (j + 1);
		if (c == kBtFree) bits[i / 4] |= 1u << j;
		if (c == kBtInner) bits[i / 4] |= 3u << j;
		out.nodes += c != kBtUnknown;
		out.leaves += c == kBtOccupied || c == kBtFree;
	}
	out.code = kBtInner;
	out.bytes.assign(reinterpret_cast<const char*>(bits), 2);
	for (const auto& c : child)
		if (c.code == kBtInner) out.bytes += c.bytes, out.nodes += c.nodes, out.leaves += c.leaves;
	return out;
}
}  // namespace

std::size_t writeOccupancyBt(const std::string& path, const CSemanticOcTree& tree)
{
	// The .bt format is the same for every occupancy tree, but OctoMap's readers refuse a tree type
	// they do not know: the header names OctoMap's own OcTree, so that octovis and octomap_server
	// read it. Written here rather than by OctoMap's writeBinaryData, which can only say occupied
	// or free: a voxel whose evidence does not settle it (a surface seen from one keyframe, or
	// seen and later passed by rays) would be free to a planner (issue 43). Such voxels are left
	// out of the file: unknown, as what was never seen.
	std::string data;
	std::size_t size = 0, leaves = 0;
	if (tree.getRoot())
	{
		TBtSubtree root = btChildren(tree, *tree.getRoot());
		if (root.code != kBtUnknown)
		{
			if (root.code != kBtInner)
			{
				// Uniformly occupied or free: the root with eight such leaves.
				const std::uint8_t b = root.code == kBtOccupied ? 0xAA : 0x55;
				root.bytes.assign({static_cast<char>(b), static_cast<char>(b)});
				root.nodes = root.leaves = 8;
			}
			data = std::move(root.bytes);
			size = root.nodes + 1;
			leaves = root.leaves;
		}
	}
	std::ostringstream s(std::ios::binary);
	s << "# Octomap OcTree binary file\n# occupancy of a yesslam semantic map (labels: map.ot); unknown: surfaces seen "
		 "but not confirmed\n";
	s << "id OcTree\nsize " << size << "\nres " << tree.getResolution() << "\ndata\n";
	s << data;
	writeFileAtomically(path, s.str());
	return leaves;
}

mrpt::opengl::CSetOfObjects::Ptr semanticOcTreeObject(const CSemanticOcTree& tree,
													  const std::vector<std::string>& names, bool byLabel)
{
	auto set = mrpt::opengl::CSetOfObjects::Create();
	set->setName("octomap");
	auto vox = mrpt::opengl::COctoMapVoxels::Create();
	vox->setName("octomap_voxels");
	vox->resizeVoxelSets(2);
	vox->showGridLines(false);
	vox->showVoxels(mrpt::opengl::VOXEL_SET_FREESPACE, false);
	vox->enableLights(true);
	std::map<TSemLabel, std::size_t> present;
	double minx = 1e9, miny = 1e9, minz = 1e9, maxx = -1e9, maxy = -1e9, maxz = -1e9;
	for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it)
	{
		if (!tree.isNodeOccupied(*it)) continue;
		const auto c = it.getCoordinate();
		const CSemanticOcTreeNode& n = *it;
		cv::Vec3b col = byLabel ? labelColour(n.label) : cv::Vec3b(n.b, n.g, n.r);
		vox->push_back_Voxel(
			mrpt::opengl::VOXEL_SET_OCCUPIED,
			mrpt::opengl::COctoMapVoxels::TVoxel(mrpt::math::TPoint3Df(c.x(), c.y(), c.z()), it.getSize(),
												 mrpt::img::TColor(col[2], col[1], col[0])));
		present[n.label]++;
		minx = std::min<double>(minx, c.x()), miny = std::min<double>(miny, c.y()),
		minz = std::min<double>(minz, c.z());
		maxx = std::max<double>(maxx, c.x()), maxy = std::max<double>(maxy, c.y()),
		maxz = std::max<double>(maxz, c.z());
	}
	if (present.empty()) return set;
	vox->setBoundingBox({minx, miny, minz}, {maxx, maxy, maxz});
	set->insert(vox);
	if (!byLabel) return set;
	// The legend: each label's name and voxel count in its colour, the most frequent first, kept as
	// data (a hidden set named "legend") that yesslam-render draws as an overlay on the picture;
	// placed in 3D beside the map it was edge-on, tiny or out of the picture from most viewpoints.
	std::vector<std::pair<std::size_t, TSemLabel>> order;
	for (const auto& [l, n] : present) order.emplace_back(n, l);
	std::sort(order.rbegin(), order.rend());
	auto legend = mrpt::opengl::CSetOfObjects::Create();
	legend->setName("legend");
	legend->setVisibility(false);
	for (const auto& [n, l] : order)
	{
		const cv::Vec3b col = labelColour(l);
		auto text = mrpt::opengl::CText::Create(labelName(l, names) + " (" + std::to_string(n) + ")");
		text->setName("legend_" + labelName(l, names));
		text->setColor_u8(col[2], col[1], col[0]);
		legend->insert(text);
	}
	set->insert(legend);
	return set;
}
}  // namespace mrpt_yesslam
