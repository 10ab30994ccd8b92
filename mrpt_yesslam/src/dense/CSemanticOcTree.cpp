#include "mrpt_yesslam/dense/CSemanticOcTree.h"

#include <octomap/AbstractOcTree.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <cstdio>
#include <sstream>

#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
std::istream& CSemanticOcTreeNode::readData(std::istream& s)
{
	s.read(reinterpret_cast<char*>(&value), sizeof(value));
	s.read(reinterpret_cast<char*>(&r), 1);
	s.read(reinterpret_cast<char*>(&g), 1);
	s.read(reinterpret_cast<char*>(&b), 1);
	s.read(reinterpret_cast<char*>(&label), 1);
	s.read(reinterpret_cast<char*>(&labelProb), sizeof(labelProb));
	return s;
}

std::ostream& CSemanticOcTreeNode::writeData(std::ostream& s) const
{
	s.write(reinterpret_cast<const char*>(&value), sizeof(value));
	s.write(reinterpret_cast<const char*>(&r), 1);
	s.write(reinterpret_cast<const char*>(&g), 1);
	s.write(reinterpret_cast<const char*>(&b), 1);
	s.write(reinterpret_cast<const char*>(&label), 1);
	s.write(reinterpret_cast<const char*>(&labelProb), sizeof(labelProb));
	return s;
}

CSemanticOcTree::TRegistration CSemanticOcTree::registration_;

CSemanticOcTree::TRegistration::TRegistration()
{
	// OctoMap keeps the prototype for the life of the program (as for its own trees).
	auto* tree = new CSemanticOcTree(0.1);
	tree->clearKeyRays();
	octomap::AbstractOcTree::registerTreeType(tree);
}

CSemanticOcTree::CSemanticOcTree(double resolution) : octomap::OccupancyOcTreeBase<CSemanticOcTreeNode>(resolution)
{
	registration_.ensureLinking();
}

void CSemanticOcTree::updateNodeLogOdds(CSemanticOcTreeNode* node, const float& update) const
{
	// Positive log-odds only come from hits (a new voxel starts at 0 and misses lower it), so a
	// voxel that is > 0 now, or is being hit, has seen a surface.
	const bool seen = update > 0 || node->getLogOdds() > 0;
	octomap::OccupancyOcTreeBase<CSemanticOcTreeNode>::updateNodeLogOdds(node, update);
	if (seen && node->getLogOdds() < kSeenLogOdds) node->setLogOdds(kSeenLogOdds);
}

void CSemanticOcTree::insertScan(const octomap::Pointcloud& scan, const octomap::point3d& origin, double clearMargin,
								 double pointSpacing)
{
	// As OctoMap's discretised insertion: one ray per hit cell, to its centre.
	octomap::KeySet hits, reached, passed;
	std::vector<octomap::point3d> ends;
	const float r = static_cast<float>(pointSpacing);
	for (const auto& p : scan)
	{
		octomap::OcTreeKey k;
		if (!coordToKeyChecked(p, k)) continue;
		if (hits.insert(k).second) ends.push_back(keyToCoord(k));
		if (!(r > 0)) continue;
		// The cells within pointSpacing of the point: those of the 26 points p + (dx, dy, dz) * r,
		// dx, dy, dz in {-1, 0, 1}. Each axis gives at most three distinct keys (the point's and its two
		// offsets'; one or two when the spacing is under a cell), so the cells are their product,
		// inserted once each instead of 26 lookups and insertions (the build's largest cost). The
		// product also holds the point's own cell, which is a hit and so never changed as reached.
		octomap::key_type axis[3][3];
		int n[3] = {0, 0, 0};
		for (unsigned a = 0; a < 3; a++)
			for (const int d : {-1, 0, 1})
			{
				octomap::key_type key;
				if (!coordToKeyChecked(p(a) + static_cast<float>(d) * r, key)) continue;
				if (std::find(axis[a], axis[a] + n[a], key) == axis[a] + n[a]) axis[a][n[a]++] = key;
			}
		for (int i = 0; i < n[0]; i++)
			for (int j = 0; j < n[1]; j++)
				for (int l = 0; l < n[2]; l++) reached.insert(octomap::OcTreeKey(axis[0][i], axis[1][j], axis[2][l]));
	}
	octomap::KeyRay ray;
	for (const auto& e : ends)
	{
		const octomap::point3d d = e - origin;
		const double len = d.norm();
		if (!(len > clearMargin)) continue;
		if (computeRayKeys(origin, origin + d * static_cast<float>((len - clearMargin) / len), ray))
			passed.insert(ray.begin(), ray.end());
	}
	for (const auto& k : passed)
		if (!hits.count(k) && !reached.count(k)) updateNode(k, false, true);
	for (const auto& k : hits) updateNode(k, true, true);
	for (const auto& k : reached)
	{
		if (hits.count(k)) continue;
		// Onto the floor from wherever it is (a positive update: seen), unless it is above it.
		const CSemanticOcTreeNode* n = search(k);
		const float v = n ? n->getLogOdds() : 0.f;
		if (v < kSeenLogOdds) updateNode(k, kSeenLogOdds - v, true);
	}
}

std::string CSemanticOcTree::otBytes() const
{
	std::ostringstream out(std::ios::binary);
	if (!write(out)) throw std::runtime_error("OctoMap could not write the semantic octree");
	std::string s = out.str();
	const auto eol = s.find('\n');
	char line[96];
	std::snprintf(line, sizeof(line), "# yesslam occupancy_threshold %.9g\n", getOccupancyThres());
	return s.insert(eol == std::string::npos ? s.size() : eol + 1, line);
}

void CSemanticOcTree::updateInnerSemantics()
{
	if (root) updateInnerSemanticsRecurs(root, 0);
}

void CSemanticOcTree::updateInnerSemanticsRecurs(CSemanticOcTreeNode* node, unsigned depth)
{
	if (!nodeHasChildren(node)) return;
	std::uint32_t r = 0, g = 0, b = 0, n = 0;
	std::array<float, 256> mass{};
	for (unsigned i = 0; i < 8; i++)
	{
		if (!nodeChildExists(node, i)) continue;
		CSemanticOcTreeNode* c = getNodeChild(node, i);
		if (depth + 1 < tree_depth) updateInnerSemanticsRecurs(c, depth + 1);
		if (!isNodeOccupied(c)) continue;
		r += c->r, g += c->g, b += c->b, n++;
		mass[c->label] += c->labelProb;
	}
	node->updateOccupancyChildren();
	if (n == 0) return;  // free space: no colour or label to show
	node->r = static_cast<std::uint8_t>(r / n);
	node->g = static_cast<std::uint8_t>(g / n);
	node->b = static_cast<std::uint8_t>(b / n);
	const auto best = std::max_element(mass.begin(), mass.end());
	node->label = static_cast<std::uint8_t>(best - mass.begin());
	node->labelProb = *best / static_cast<float>(n);
}

namespace
{
// OctoMap's reader trusts the file: a flipped child bit makes it recurse and allocate without end.
// So the node structure is walked here first: header fields, 12-byte records each followed by a
// child-bit byte, no deeper than the tree's 16 levels, `size` nodes, ending with the file.
std::optional<double> checkStructure(const std::string& path, std::istream& in)
{
	std::optional<double> threshold;
	std::string line, id;
	std::size_t size = 0;
	bool haveSize = false, haveRes = false;
	std::getline(in, line);
	if (line.rfind("# Octomap OcTree file", 0) != 0)
		throw InputError(path, "not an OctoMap .ot file (it does not start with '# Octomap OcTree file')");
	while (std::getline(in, line) && line != "data")
	{
		if (line.rfind("# yesslam occupancy_threshold ", 0) == 0)
		{
			double t = 0;
			if (std::istringstream(line.substr(30)) >> t && t > 0 && t < 1) threshold = t;
		}
		if (line.empty() || line[0] == '#') continue;
		std::istringstream l(line);
		std::string key;
		l >> key;
		if (key == "id")
			l >> id;
		else if (key == "size")
			haveSize = static_cast<bool>(l >> size);
		else if (key == "res")
		{
			double r = 0;
			haveRes = static_cast<bool>(l >> r) && r > 0 && std::isfinite(r);
		}
	}
	if (line != "data" || !haveSize || !haveRes || id.empty())
		throw InputError(path, "corrupt OctoMap header (needs id, size, res and data lines)");
	if (id != "YesSlamSemanticOcTree")
		throw InputError(path,
						 "holds an octree of type " + id + ", not a yesslam semantic octree (YesSlamSemanticOcTree)");
	const std::streamoff start = in.tellg();
	in.seekg(0, std::ios::end);
	const std::streamoff bytes = in.tellg() - start;
	constexpr std::streamoff kNode = 13;  // record + child bits
	if (size == 0 || bytes != static_cast<std::streamoff>(size) * kNode)
		throw InputError(path, "corrupt or truncated OctoMap file: " + std::to_string(bytes) +
								   " bytes of tree data for " + std::to_string(size) + " nodes");
	std::string data(static_cast<std::size_t>(bytes), '\0');
	in.seekg(start);
	in.read(data.data(), bytes);
	std::vector<int> pending{1};  // children still to read, per depth
	std::size_t nodes = 0;
	while (!pending.empty())
	{
		if (pending.back() == 0)
		{
			pending.pop_back();
			continue;
		}
		pending.back()--;
		if (nodes >= size) throw InputError(path, "corrupt OctoMap file: more nodes in the tree than its header says");
		const auto bits = static_cast<unsigned char>(data[nodes * kNode + kNode - 1]);
		nodes++;
		if (bits)
		{
			if (pending.size() > 16) throw InputError(path, "corrupt OctoMap file: the tree is deeper than 16 levels");
			pending.push_back(__builtin_popcount(bits));
		}
	}
	if (nodes != size)
		throw InputError(path, "corrupt OctoMap file: " + std::to_string(nodes) + " nodes in the tree, " +
								   std::to_string(size) + " in its header");
	in.clear();
	in.seekg(0);
	return threshold;
}
}  // namespace

std::unique_ptr<CSemanticOcTree> CSemanticOcTree::readFile(const std::string& path)
{
	if (!std::filesystem::is_regular_file(path)) throw InputError(path, "not found (or not a file)");
	std::ifstream in(path, std::ios::binary);
	if (!in) throw InputError(path, "cannot open");
	return read(in, path);
}

std::unique_ptr<CSemanticOcTree> CSemanticOcTree::read(std::istream& in, const std::string& path)
{
	const auto start = in.tellg();
	const std::optional<double> threshold = checkStructure(path, in);
	in.clear();
	in.seekg(start);
	// OctoMap's AbstractOcTree::read, with the tree owned from the start: that one creates the tree
	// and leaks it when reading its nodes throws (a stream that fails half-way). The header was
	// checked above (the tree type is ours).
	// OctoMap reports its progress on std::cout and std::cerr: not for our users. The streams are
	// restored however the read ends (an exception left them on the destroyed buffer before).
	struct TQuiet
	{
		std::ostringstream sink;
		std::streambuf* out = std::cout.rdbuf(sink.rdbuf());
		std::streambuf* err = std::cerr.rdbuf(sink.rdbuf());
		~TQuiet()
		{
			std::cout.rdbuf(out);
			std::cerr.rdbuf(err);
		}
	};
	TQuiet quiet;
	std::string line, id;
	unsigned size = 0;
	double res = 0;
	std::getline(in, line);
	if (line.compare(0, fileHeader.size(), fileHeader) != 0 || !readHeader(in, id, size, res) || !(res > 0))
		throw InputError(path, "corrupt OctoMap file (OctoMap could not read its header)");
	auto tree = std::make_unique<CSemanticOcTree>(res);
	if (threshold) tree->setOccupancyThres(*threshold);
	if (size > 0) tree->readData(in);
	if (!in) throw InputError(path, "corrupt OctoMap file (OctoMap could not read it)");
	return tree;
}
}  // namespace mrpt_yesslam
