#include "mrpt_yesslam/dense/COccupancyGridBuilder.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace mrpt_yesslam
{
bool TOccupancyGrid2D::cellOf(double x, double y, int& i, int& j) const
{
	const double fi = std::floor((x - originX) / resolution), fj = std::floor((y - originY) / resolution);
	if (!(fi >= 0 && fi < width && fj >= 0 && fj < height)) return false;
	i = static_cast<int>(fi), j = static_cast<int>(fj);
	return true;
}

std::size_t TOccupancyGrid2D::count(std::int8_t value) const
{
	return static_cast<std::size_t>(std::count(cells.begin(), cells.end(), value));
}

COptionTable COccupancyGridBuilder::TOptions::table()
{
	COptionTable t("Grid2D");
	t.flag("enabled", enabled,
		   "write the 2D occupancy grid (map_2d.gridmap, map_2d.pgm + map_2d.yaml, map_2d.png) with the dense map; "
		   "only in the z-up world frame");
	t.real("resolution", resolution, 0.01, 1, "cell size, m");
	t.real("minHeight", minHeight, -1, 10,
		   "bottom of the height band projected into the grid, m above the floor (above the floor's own noise)");
	t.real("maxHeight", maxHeight, 0, 10, "top of the band, m above the floor (the robot's height)");
	t.real("footprintRadius", footprintRadius, 0, 5,
		   "cells this near the camera's path are free (the robot was there) unless a static surface was seen in "
		   "the band there, m");
	t.real("cameraHeight", cameraHeight, 0, 10,
		   "the first camera's height above the floor when the run saw no floor (the band is measured from there), "
		   "m");
	return t;
}

namespace
{
constexpr std::size_t kMaxCells = std::size_t{1} << 25;

// What the band's voxels over one cell say, strongest first; a cell takes the strongest.
enum ERank : std::uint8_t
{
	kNothing = 0,
	kRayFree = 1,
	kSurface = 2,  // a surface seen but not confirmed, or a dynamic object's: neither free nor an obstacle
	kObstacle = 3
};

struct TFootprint
{
	double x0, x1, y0, y1;
	ERank rank;
};
}  // namespace

namespace
{
// The leaves of the band (a leaf counts where at least half a voxel of it lies in the band: a voxel at
// the tree's resolution where its centre does, so the floor's top layer never does) with their rank.
std::vector<TFootprint> bandLeaves(const CSemanticOcTree& tree, const std::set<std::uint8_t>& dynamicLabels,
								   double minZ, double maxZ)
{
	std::vector<TFootprint> leaves;
	if (!tree.getRoot()) return leaves;
	double mx, my, mz, Mx, My, Mz;
	tree.getMetricMin(mx, my, mz);
	tree.getMetricMax(Mx, My, Mz);
	const octomap::point3d bmin{float(mx), float(my), float(minZ)}, bmax{float(Mx), float(My), float(maxZ)};
	const double need = 0.5 * tree.getResolution();
	for (auto it = tree.begin_leafs_bbx(bmin, bmax), end = tree.end_leafs_bbx(); it != end; ++it)
	{
		const double s = it.getSize(), cz = it.getZ();
		if (std::min(cz + s / 2, maxZ) - std::max(cz - s / 2, minZ) < std::min(need, s / 2)) continue;
		ERank rank = kRayFree;
		switch (tree.stateOf(*it))
		{
			case EVoxelState::Occupied: rank = dynamicLabels.count(it->label) ? kSurface : kObstacle; break;
			case EVoxelState::Unknown: rank = kSurface; break;
			case EVoxelState::Free: rank = kRayFree; break;
		}
		const double x0 = it.getX() - s / 2, y0 = it.getY() - s / 2;
		leaves.push_back({x0, x0 + s, y0, y0 + s, rank});
	}
	return leaves;
}

// Sizes `g` to hold the leaves and the path's footprint (radius `rf`), on the resolution's lattice
// with one cell of margin; false when there is nothing to hold.
bool sizeGrid(TOccupancyGrid2D& g, const std::vector<TFootprint>& leaves, const std::vector<mrpt::math::TPoint3D>& path,
			  double rf)
{
	double lo[2] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max()};
	double hi[2] = {-lo[0], -lo[1]};
	const auto grow = [&](double x0, double x1, double y0, double y1)
	{
		lo[0] = std::min(lo[0], x0), hi[0] = std::max(hi[0], x1);
		lo[1] = std::min(lo[1], y0), hi[1] = std::max(hi[1], y1);
	};
	for (const auto& l : leaves) grow(l.x0, l.x1, l.y0, l.y1);
	for (const auto& p : path) grow(p.x - rf, p.x + rf, p.y - rf, p.y + rf);
	if (lo[0] > hi[0]) return false;
	const double r = g.resolution;
	g.originX = (std::floor(lo[0] / r) - 1) * r;
	g.originY = (std::floor(lo[1] / r) - 1) * r;
	// A bounded grid: a pose gone far astray must not ask for gigabytes (2^25 cells: 290 m square at 5 cm).
	const double w = std::ceil((hi[0] - g.originX) / r) + 1, h = std::ceil((hi[1] - g.originY) / r) + 1;
	if (!(w * h <= double(kMaxCells)))
		throw std::invalid_argument("the 2D grid would span " + std::to_string(std::lround(hi[0] - lo[0])) + " x " +
									std::to_string(std::lround(hi[1] - lo[1])) + " m, over " +
									std::to_string(kMaxCells) + " cells (a pose far astray? a coarser resolution)");
	g.width = static_cast<int>(w);
	g.height = static_cast<int>(h);
	return true;
}

// The cells [i0, i1] along one axis that a span [a0, a1) reaches: those whose centre it covers, or
// with `overlap` every cell it overlaps (a wall one voxel thick is never lost between the centres
// of larger cells). The tolerance (in cells) absorbs OctoMap's float coordinates on the lattice.
void cellSpan(double a0, double a1, double origin, double r, int n, bool overlap, int& i0, int& i1)
{
	const double e = 1e-3, f0 = (a0 - origin) / r, f1 = (a1 - origin) / r;
	i0 = std::max(0, static_cast<int>(overlap ? std::floor(f0 + e) : std::ceil(f0 - 0.5)));
	i1 = std::min(n - 1, static_cast<int>(overlap ? std::ceil(f1 - e) : std::ceil(f1 - 0.5)) - 1);
}

// The cells within `rf` of each camera position, and the camera's own cell, become free where no
// static surface was seen.
void clearFootprint(const TOccupancyGrid2D& g, const std::vector<mrpt::math::TPoint3D>& path, double rf,
					std::vector<std::uint8_t>& rank)
{
	const double r = g.resolution;
	for (const auto& p : path)
	{
		int i0, i1, j0, j1;
		cellSpan(p.x - rf, p.x + rf, g.originX, r, g.width, false, i0, i1);
		cellSpan(p.y - rf, p.y + rf, g.originY, r, g.height, false, j0, j1);
		int pi = -1, pj = -1;
		if (g.cellOf(p.x, p.y, pi, pj))
			i0 = std::min(i0, pi), i1 = std::max(i1, pi), j0 = std::min(j0, pj), j1 = std::max(j1, pj);
		for (int j = j0; j <= j1; j++)
			for (int i = i0; i <= i1; i++)
			{
				const double dx = g.originX + (i + 0.5) * r - p.x, dy = g.originY + (j + 0.5) * r - p.y;
				auto& c = rank[static_cast<std::size_t>(j) * g.width + i];
				if ((dx * dx + dy * dy <= rf * rf || (i == pi && j == pj)) && c < kObstacle) c = kRayFree;
			}
	}
}
}  // namespace

TOccupancyGrid2D COccupancyGridBuilder::build(const CSemanticOcTree& tree, const std::set<std::uint8_t>& dynamicLabels,
											  const std::vector<mrpt::math::TPoint3D>& path, double floorZ,
											  bool floorSeen) const
{
	if (!(opts_.maxHeight > opts_.minHeight)) throw std::invalid_argument("[Grid2D] maxHeight must be above minHeight");
	if (!(opts_.resolution >= 0.001 && opts_.resolution <= 10))
		throw std::invalid_argument("[Grid2D] resolution must be between 0.001 and 10 m");
	TOccupancyGrid2D g;
	g.resolution = opts_.resolution;
	g.floorZ = floorZ;
	g.floorSeen = floorSeen;
	g.minZ = floorZ + opts_.minHeight;
	g.maxZ = floorZ + opts_.maxHeight;
	const std::vector<TFootprint> leaves = bandLeaves(tree, dynamicLabels, g.minZ, g.maxZ);
	if (!sizeGrid(g, leaves, path, opts_.footprintRadius)) return g;  // nothing seen, no path: an empty grid
	// Each cell takes the strongest of the leaves that reach it, then the footprint.
	std::vector<std::uint8_t> rank(static_cast<std::size_t>(g.width) * g.height, kNothing);
	for (const auto& l : leaves)
	{
		int i0, i1, j0, j1;
		cellSpan(l.x0, l.x1, g.originX, g.resolution, g.width, l.rank >= kSurface, i0, i1);
		cellSpan(l.y0, l.y1, g.originY, g.resolution, g.height, l.rank >= kSurface, j0, j1);
		for (int j = j0; j <= j1; j++)
			for (int i = i0; i <= i1; i++)
			{
				auto& c = rank[static_cast<std::size_t>(j) * g.width + i];
				c = std::max<std::uint8_t>(c, l.rank);
			}
	}
	clearFootprint(g, path, opts_.footprintRadius, rank);
	g.cells.resize(rank.size());
	for (std::size_t k = 0; k < rank.size(); k++)
		g.cells[k] = rank[k] == kObstacle
						 ? TOccupancyGrid2D::kOccupied
						 : (rank[k] == kRayFree ? TOccupancyGrid2D::kFree : TOccupancyGrid2D::kUnknown);
	return g;
}
}  // namespace mrpt_yesslam
