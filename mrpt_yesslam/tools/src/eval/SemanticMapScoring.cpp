#include "mrpt_yesslam/eval/SemanticMapScoring.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>
#include <set>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
namespace
{
// Every frame of a yesslam-sim folder: `onFrame(camera pose in the map frame)`; every `frameStep`-th
// also `onPoint(x, y, z in the map frame, moving, class)` for every `pixelStep`-th pixel with depth.
void forEachSimPoint(const std::string& simDir, const mrpt::poses::CPose3D& mapInGt, int frameStep, int pixelStep,
					 const std::function<void(const mrpt::poses::CPose3D&)>& onFrame,
					 const std::function<void(double, double, double, bool, int)>& onPoint)
{
	const fs::path dir(simDir);
	for (const char* f : {"objects.txt", "depth.txt", "rgb.txt", "groundtruth.txt", "calibration.txt"})
		if (!fs::exists(dir / f)) throw InputError((dir / f).string(), "not found: scoring needs a yesslam-sim folder");
	// The labels are the colour image's: a depth image taken at another moment (--depth-offset,
	// the crowd preset) does not see what they label where things move.
	{
		const auto rgb = readTumFileList((dir / "rgb.txt").string()),
				   depth = readTumFileList((dir / "depth.txt").string());
		for (std::size_t k = 0; k < rgb.size() && k < depth.size(); k++)
			if (std::abs(rgb[k].t - depth[k].t) > 1e-3)
				throw InputError((dir / "depth.txt").string(),
								 "its depth images were taken at other moments than their colour images and labels "
								 "(yesslam-sim --depth-offset): "
								 "scoring needs them together; make the sequence with --depth-offset 0");
	}
	// Intrinsics: "fx fy cx cy width height depth_scale" on the first line that is not a comment.
	double fx = 0, fy = 0, cx = 0, cy = 0, scale = 0;
	for (const auto& line : splitLines(readTextFile((dir / "calibration.txt").string())))
	{
		const auto f = splitFields(line);
		if (f.empty() || f[0][0] == '#') continue;
		if (f.size() < 7)
			throw InputError((dir / "calibration.txt").string(), "expected fx fy cx cy width height depth_scale");
		fx = std::stod(f[0]), fy = std::stod(f[1]), cx = std::stod(f[2]), cy = std::stod(f[3]), scale = std::stod(f[6]);
		break;
	}
	if (!(fx > 0 && scale > 0)) throw InputError((dir / "calibration.txt").string(), "no intrinsics");
	std::set<int> moving;  // instances that move at any time
	for (const auto& line : splitLines(readTextFile((dir / "objects.txt").string())))
	{
		const auto f = splitFields(line);
		if (f.size() >= 10 && f[0][0] != '#' && f[9] == "1") moving.insert(std::stoi(f[1]));
	}
	const TTrajectory gt = readTumTrajectory((dir / "groundtruth.txt").string());
	auto gtAt = [&](double t)
	{
		const auto it = std::min_element(
			gt.begin(), gt.end(), [&](const auto& a, const auto& b) { return std::abs(a.t - t) < std::abs(b.t - t); });
		return it->asPose();
	};
	const mrpt::poses::CPose3D gtToMap = -mapInGt;

	int index = 0;
	for (const auto& line : splitLines(readTextFile((dir / "depth.txt").string())))
	{
		const auto f = splitFields(line);
		if (f.size() < 2 || f[0][0] == '#') continue;
		const mrpt::poses::CPose3D T = gtToMap + gtAt(std::stod(f[0]));  // camera in the map frame
		onFrame(T);
		if (index++ % frameStep) continue;
		const std::string name = fs::path(f[1]).filename().string();
		const cv::Mat depth = cv::imread((dir / f[1]).string(), cv::IMREAD_UNCHANGED);
		const cv::Mat cls = cv::imread((dir / "labels/class" / name).string(), cv::IMREAD_UNCHANGED);
		const cv::Mat inst = cv::imread((dir / "labels/instance" / name).string(), cv::IMREAD_UNCHANGED);
		if (depth.empty() || cls.empty() || inst.empty() || depth.type() != CV_16U || cls.size() != depth.size() ||
			inst.size() != depth.size())
			throw InputError((dir / f[1]).string(), "depth or labels/ image missing or of the wrong type");
		for (int v = 0; v < depth.rows; v += pixelStep)
			for (int u = 0; u < depth.cols; u += pixelStep)
			{
				const double z = depth.at<std::uint16_t>(v, u) / scale;
				if (z <= 0) continue;
				double x, y, w;
				T.composePoint((u - cx) * z / fx, (v - cy) * z / fy, z, x, y, w);
				const int id = inst.type() == CV_16U ? inst.at<std::uint16_t>(v, u) : inst.at<std::uint8_t>(v, u);
				onPoint(x, y, w, moving.count(id) > 0,
						cls.type() == CV_16U ? cls.at<std::uint16_t>(v, u) : cls.at<std::uint8_t>(v, u));
			}
	}
}
}  // namespace

TSemanticMapScore scoreSemanticMap(const CSemanticOcTree& tree, const std::string& simDir,
								   const mrpt::poses::CPose3D& mapInGt, int frameStep, int pixelStep)
{
	using Key = octomap::OcTreeKey;
	std::unordered_set<Key, Key::KeyHash> swept;
	std::unordered_map<Key, std::map<int, std::uint32_t>, Key::KeyHash> surface;  // label -> pixels
	forEachSimPoint(
		simDir, mapInGt, frameStep, pixelStep, [](const mrpt::poses::CPose3D&) {},
		[&](double x, double y, double z, bool moving, int cls)
		{
			Key k;
			if (!tree.coordToKeyChecked(octomap::point3d(float(x), float(y), float(z)), k)) return;
			if (moving)
				swept.insert(k);
			else
				surface[k][cls]++;
		});
	TSemanticMapScore s;
	auto occupied = [&](const Key& k)
	{
		const CSemanticOcTreeNode* n = tree.search(k);
		return n && tree.isNodeOccupied(n) ? n : nullptr;
	};
	for (const Key& k : swept)
	{
		bool nearStatic = false;
		for (int dx = -1; dx <= 1 && !nearStatic; dx++)
			for (int dy = -1; dy <= 1 && !nearStatic; dy++)
				for (int dz = -1; dz <= 1 && !nearStatic; dz++)
					nearStatic = surface.count(Key(static_cast<octomap::key_type>(k[0] + dx),
												   static_cast<octomap::key_type>(k[1] + dy),
												   static_cast<octomap::key_type>(k[2] + dz))) > 0;
		if (nearStatic) continue;
		s.sweptVoxels++;
		if (occupied(k)) s.ghostVoxels++;
	}
	for (const auto& [k, counts] : surface)
	{
		const CSemanticOcTreeNode* n = occupied(k);
		if (!n) continue;
		const int truth = std::max_element(counts.begin(), counts.end(),
										   [](const auto& a, const auto& b) { return a.second < b.second; })
							  ->first;
		const bool ok = n->label == truth;
		s.scoredVoxels++;
		s.labelCorrect += ok;
		auto& pl = s.perLabel[truth];
		pl.first += ok, pl.second++;
		if (truth > 0) s.objectVoxels++, s.objectCorrect += ok;
		if (n->label > 0) s.labelledObjectVoxels++, s.labelledObjectCorrect += ok;
	}
	return s;
}

TGridScore scoreGrid2D(const TOccupancyGrid2D& grid, const std::string& simDir, const mrpt::poses::CPose3D& mapInGt,
					   int frameStep, int pixelStep)
{
	const auto key = [&](double x, double y) -> std::optional<std::pair<int, int>>
	{
		int i, j;
		if (!grid.cellOf(x, y, i, j)) return std::nullopt;
		return std::make_pair(i, j);
	};
	if (!(grid.maxZ > grid.minZ))
		throw std::invalid_argument(
			"scoreGrid2D: the grid's band (minZ, maxZ) is not set (readRosMap does not know it)");
	std::set<std::pair<int, int>> path, staticCells, sweptCells;
	TGridScore sc;
	forEachSimPoint(
		simDir, mapInGt, frameStep, pixelStep,
		[&](const mrpt::poses::CPose3D& cam)
		{
			// Every frame's camera, outside the grid too (a cell never seen is a failure).
			if (const auto c = key(cam.x(), cam.y()))
				path.insert(*c);
			else
				sc.pathCellsOutside++;
		},
		[&](double x, double y, double z, bool moving, int)
		{
			if (z < grid.minZ || z > grid.maxZ) return;
			if (const auto c = key(x, y)) (moving ? sweptCells : staticCells).insert(*c);
		});
	const auto occupiedNear = [&](const std::pair<int, int>& c, int reach)
	{
		for (int dj = -reach; dj <= reach; dj++)
			for (int di = -reach; di <= reach; di++)
			{
				const int i = c.first + di, j = c.second + dj;
				if (i >= 0 && j >= 0 && i < grid.width && j < grid.height &&
					grid.at(i, j) == TOccupancyGrid2D::kOccupied)
					return true;
			}
		return false;
	};
	for (const auto& c : path)
	{
		sc.pathCells++;
		sc.pathFree += grid.at(c.first, c.second) == TOccupancyGrid2D::kFree;
	}
	for (const auto& c : staticCells)
	{
		sc.staticCells++;
		sc.staticOccupied += occupiedNear(c, 1);
	}
	for (const auto& c : sweptCells)
	{
		bool nearStatic = false;
		for (int dj = -1; dj <= 1 && !nearStatic; dj++)
			for (int di = -1; di <= 1 && !nearStatic; di++)
				nearStatic = staticCells.count({c.first + di, c.second + dj}) > 0;
		if (nearStatic) continue;
		sc.sweptCells++;
		sc.sweptOccupied += grid.at(c.first, c.second) == TOccupancyGrid2D::kOccupied;
	}
	return sc;
}
}  // namespace mrpt_yesslam
