// The dense map's final build (CDenseSemanticMapper::build) and the stored clouds in the world.
#include "mrpt_yesslam/dense/CDenseSemanticMapper.h"

#include <cstdio>

#include <mrpt/maps/CSimplePointsMap.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <future>
#include <limits>
#include <map>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "mrpt_yesslam/util/Stopwatch.h"
#include "mrpt_yesslam/geometry/CPinholeCamera.h"
#include "DensePacking.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
using dense_detail::transform;
using dense_detail::voxelKey;

std::vector<cv::Point3f> CDenseSemanticMapper::worldPoints(
	const std::function<mrpt::poses::CPose3D(TKeyFrameId)>& poseOf, std::size_t step) const
{
	std::map<TKeyFrameId, std::shared_ptr<const TPackedCloud>> clouds;
	{
		std::lock_guard<std::mutex> lk(mtx_);
		clouds = clouds_;
	}
	std::vector<cv::Point3f> out;
	std::vector<TPackedCloud::TPoint> points;
	std::vector<std::uint8_t> planes;
	for (const auto& [id, c] : clouds)
	{
		const auto T = poseOf(id);
		c->unpack(points, planes);
		for (std::size_t i = 0; i < points.size(); i += std::max<std::size_t>(step, 1))
		{
			const auto& p = points[i];
			out.push_back(transform(T, cv::Point3f(p.x, p.y, p.z) * static_cast<float>(unit_)));
		}
	}
	return out;
}

TDenseMap CDenseSemanticMapper::build(const std::function<mrpt::poses::CPose3D(TKeyFrameId)>& poseOf) const
{
	const auto t0 = std::chrono::steady_clock::now();
	std::map<TKeyFrameId, std::shared_ptr<const TPackedCloud>> clouds;
	{
		std::lock_guard<std::mutex> lk(mtx_);
		clouds = clouds_;
	}
	TDenseMap m;
	m.keyFrames = clouds.size();
	std::string prior;
	{
		std::lock_guard<std::mutex> lk(mtx_);
		prior = prior_;
	}
	if (!prior.empty())
	{
		std::istringstream in(prior);
		auto t = CSemanticOcTree::read(in, "the loaded map's octree");
		if (std::abs(t->getResolution() - opts_.octomapResolution) < 1e-9)
		{
			m.octree = std::move(t);
			m.priorMerged = true;
		}
	}
	if (!m.octree) m.octree = std::make_unique<CSemanticOcTree>(opts_.octomapResolution);
	m.octree->setProbHit(opts_.probHit);
	m.octree->setProbMiss(opts_.probMiss);
	m.octree->setOccupancyThres(opts_.occupancyThreshold);

	// Every point by voxel: (voxel, keyframe, point) triples sorted, as PCL's VoxelGrid does, instead
	// of a hash map of every voxel (about 160 bytes each with its label vector, kept to the end of
	// the build; issue 41 item 5: the build was the run's peak of memory). 32 bytes a point (the
	// point itself with its voxel: the stored clouds are packed, not open to random access), and no
	// more than buildSlabPoints of them at a time: the voxels are taken in slabs of whole columns of x
	// (a long run's keyframes see each voxel many times, and all its points at once would outweigh
	// the hash map). The same sums in the same order (keyframes by id, then their points), and the
	// voxels in key order, slab after slab: the same map to the last bit, whatever the slabs.
	using TPoint = TPackedCloud::TPoint;
	struct TPointRef
	{
		std::int64_t key;
		std::uint32_t cloud, index;
		TPoint p;  //!< the point itself: the clouds are packed, not open to random access
	};
	std::vector<std::pair<mrpt::poses::CPose3D, const TPackedCloud*>> list;
	list.reserve(clouds.size());
	for (const auto& [id, c] : clouds) list.emplace_back(poseOf(id), c.get());
	const double inv = 1.0 / opts_.voxelSize;
	const float unit = static_cast<float>(unit_);
	const auto worldPoint = [&](std::uint32_t cloud, const TPoint& p)
	{
		return transform(list[cloud].first, cv::Point3f(p.x, p.y, p.z) * unit);  // eq. 26
	};
	const auto columnOf = [](std::int64_t key) { return key >> 42; };  // voxelKey's x field
	// The octree's cell keys, computed here from a grid of its resolution, not from the tree being built.
	const CSemanticOcTree keyGrid(m.octree->getResolution());
	// The octree on a second thread while this one sums the voxels: both only read the stored clouds and poses, and
	// each writes only its own part (the cells' colours and labels go into the octree once it is done). At the end of a
	// run the stages are idle, so the two share the run's cores (the octree is the larger part).
	// (Deferred into get() if no thread can be started.)
	auto octreeBuilt = std::async(
		std::launch::async | std::launch::deferred,
		[&]
		{
			std::vector<TPoint> points;
			std::vector<std::uint8_t> planes;
			for (std::uint32_t ci = 0; ci < list.size(); ci++)
			{
				const auto& [T, c] = list[ci];
				c->unpack(points, planes);
				octomap::Pointcloud scan;
				scan.reserve(points.size());
				for (const TPoint& p : points)
				{
					const cv::Point3f w = worldPoint(ci, p);
					scan.push_back(w.x, w.y, w.z);
				}
				// Ray casting from the camera: cells passed are observed free (a person's old place too).
				m.octree->insertScan(
					scan,
					octomap::point3d(static_cast<float>(T.x()), static_cast<float>(T.y()), static_cast<float>(T.z())),
					opts_.clearMargin, opts_.voxelSize);
			}
			m.octree->updateInnerOccupancy();
		});
	// Points per column of voxels (for the slabs), and each cloud's first and last column: a slab's
	// pass skips the clouds with no point in it instead of unpacking and transforming them again.
	std::vector<TPoint> points;
	std::vector<std::uint8_t> planes;
	std::map<std::int64_t, std::size_t> perColumn;
	std::vector<std::pair<std::int64_t, std::int64_t>> cloudColumns(
		list.size(), {std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::min()});
	for (std::uint32_t ci = 0; ci < list.size(); ci++)
	{
		list[ci].second->unpack(points, planes);
		for (const TPoint& p : points)
		{
			const std::int64_t col = columnOf(voxelKey(worldPoint(ci, p), inv));
			perColumn[col]++;
			cloudColumns[ci].first = std::min(cloudColumns[ci].first, col);
			cloudColumns[ci].second = std::max(cloudColumns[ci].second, col);
		}
	}
	// Slabs: consecutive columns up to buildSlabPoints points (a column over it is a slab of its own).
	std::vector<std::pair<std::int64_t, std::int64_t>> slabs;  // first and last column
	std::vector<std::size_t> slabPoints;
	for (const auto& [col, n] : perColumn)
	{
		if (slabs.empty() || slabPoints.back() + n > opts_.buildSlabPoints)
		{
			slabs.emplace_back(col, col);
			slabPoints.push_back(0);
		}
		slabs.back().second = col;
		slabPoints.back() += n;
	}

	// A voxel's sums over its points; only those seen from minObservations keyframes are kept.
	struct TVoxel
	{
		double x = 0, y = 0, z = 0;
		std::uint32_t b = 0, g = 0, r = 0, n = 0;
		std::uint32_t keyFrames = 0;
		TLabelBelief belief;
	};
	const int K = numLabels();
	// Every voxel of every slab, in key order (slab after slab), given to `use` with its sums: the
	// same slabs, sorts and sums each time it is called.
	const auto forEachVoxel = [&](bool withLabels, const std::function<void(const TVoxel&)>& use)
	{
		std::vector<TPointRef> refs;
		for (std::size_t s = 0; s < slabs.size(); s++)
		{
			refs.clear();
			refs.reserve(slabPoints[s]);
			for (std::uint32_t ci = 0; ci < list.size(); ci++)
			{
				if (cloudColumns[ci].second < slabs[s].first || cloudColumns[ci].first > slabs[s].second) continue;
				list[ci].second->unpack(points, planes);
				for (std::uint32_t i = 0; i < points.size(); i++)
				{
					const std::int64_t key = voxelKey(worldPoint(ci, points[i]), inv);
					if (columnOf(key) >= slabs[s].first && columnOf(key) <= slabs[s].second)
						refs.push_back({key, ci, i, points[i]});
				}
			}
			std::sort(refs.begin(), refs.end(),
					  [](const TPointRef& a, const TPointRef& b)
					  { return std::tie(a.key, a.cloud, a.index) < std::tie(b.key, b.cloud, b.index); });
			for (std::size_t i = 0; i < refs.size();)
			{
				TVoxel v;
				std::size_t j = i;
				for (; j < refs.size() && refs[j].key == refs[i].key; j++)
				{
					const TPoint& p = refs[j].p;
					const cv::Point3f w = worldPoint(refs[j].cloud, p);
					v.x += w.x, v.y += w.y, v.z += w.z;
					v.b += p.b, v.g += p.g, v.r += p.r;
					v.n++;
					if (j == i || refs[j].cloud != refs[j - 1].cloud) v.keyFrames++;
					if (withLabels && p.prob > 0) v.belief.observe(p.label, p.prob / 255.0, K);  // eq. 29
				}
				use(v);
				i = j;
			}
		}
	};
	const auto centreOf = [](const TVoxel& v) {
		return cv::Point3f(static_cast<float>(v.x / v.n), static_cast<float>(v.y / v.n), static_cast<float>(v.z / v.n));
	};
	// Two passes over the voxels instead of every voxel's sums and label evidence kept at once
	// (about 110 bytes a voxel: the build's peak of memory, issue 41 item 5): the first keeps only
	// the centres of the voxels seen often enough, for the outlier filter; the second sums them again,
	// with their labels, and writes each kept voxel's point into the cloud.
	std::vector<cv::Point3f> centres;
	forEachVoxel(false,
				 [&](const TVoxel& v)
				 {
					 m.voxelsBeforeFilter++;
					 if (v.keyFrames >= static_cast<std::uint32_t>(opts_.minObservations))
						 centres.push_back(centreOf(v));
				 });
	centres.shrink_to_fit();

	// Statistical outlier removal on MRPT's KD-tree. The cloud in a fixed order: by position.
	std::vector<std::uint32_t> idx(centres.size());
	std::iota(idx.begin(), idx.end(), 0);
	std::sort(idx.begin(), idx.end(),
			  [&](std::uint32_t a, std::uint32_t b) {
				  return std::tie(centres[a].z, centres[a].y, centres[a].x) <
						 std::tie(centres[b].z, centres[b].y, centres[b].x);
			  });
	std::vector<bool> keep(centres.size(), true);
	const std::size_t kn = static_cast<std::size_t>(opts_.outlierNeighbours);
	if (kn > 0 && centres.size() > kn + 1)
	{
		mrpt::maps::CSimplePointsMap pm;
		pm.reserve(centres.size());
		for (const auto& p : centres) pm.insertPointFast(p.x, p.y, p.z);
		std::vector<double> meanDist(centres.size());
		std::vector<size_t> nn;
		std::vector<float> d2;
		for (std::size_t i = 0; i < centres.size(); i++)
		{
			pm.kdTreeNClosestPoint3DIdx(centres[i].x, centres[i].y, centres[i].z, kn + 1, nn, d2);
			double s = 0;
			for (std::size_t j = 1; j < d2.size(); j++)
				s += std::sqrt(static_cast<double>(d2[j]));  // [0] is the point itself
			meanDist[i] = d2.size() > 1 ? s / static_cast<double>(d2.size() - 1) : 0;
		}
		const double mean =
			std::accumulate(meanDist.begin(), meanDist.end(), 0.0) / static_cast<double>(meanDist.size());
		double var = 0;
		for (const double d : meanDist) var += (d - mean) * (d - mean);
		const double limit = mean + opts_.outlierStdDev * std::sqrt(var / static_cast<double>(meanDist.size()));
		for (std::size_t i = 0; i < centres.size(); i++)
			if (meanDist[i] > limit)
			{
				keep[i] = false;
				m.outliersRemoved++;
			}
	}
	// Each kept voxel's place in the cloud (its rank by position among the kept ones).
	constexpr std::uint32_t kDropped = std::numeric_limits<std::uint32_t>::max();
	std::vector<std::uint32_t> place(centres.size(), kDropped);
	std::uint32_t kept = 0;
	for (const std::uint32_t i : idx)
		if (keep[i]) place[i] = kept++;
	std::vector<std::uint32_t>().swap(idx);
	auto& c = m.cloud;
	c.xyz.resize(kept);
	c.bgr.resize(kept);
	c.label.resize(kept);
	c.labelProb.resize(kept);
	c.observations.resize(kept);

	// The cloud, and the octree's occupied cells get colour and fused label from the points in them.
	// A cell's voxels are merged in key order (before the two passes: by position), a fixed order,
	// the same whatever the slabs; their label evidence sums may differ in the last bits from the
	// order before (the map files of the runs checked were the same to the byte).
	struct TCell
	{
		std::uint32_t b = 0, g = 0, r = 0, n = 0;
		TLabelBelief belief;
	};
	std::unordered_map<octomap::OcTreeKey, TCell, octomap::OcTreeKey::KeyHash> cells;
	std::size_t i = 0;  // the voxel's index among those seen often enough (as in the first pass)
	forEachVoxel(true,
				 [&](const TVoxel& v)
				 {
					 if (v.keyFrames < static_cast<std::uint32_t>(opts_.minObservations)) return;
					 const std::uint32_t at = place[i++];
					 if (at == kDropped) return;
					 const auto [label, prob] = v.belief.best(K);
					 c.xyz[at] = centreOf(v);
					 c.bgr[at] = cv::Vec3b(static_cast<uchar>(v.b / v.n), static_cast<uchar>(v.g / v.n),
										   static_cast<uchar>(v.r / v.n));
					 c.label[at] = label;
					 c.labelProb[at] = static_cast<float>(prob);
					 c.observations[at] = v.keyFrames;
					 octomap::OcTreeKey key;
					 if (!keyGrid.coordToKeyChecked(octomap::point3d(c.xyz[at].x, c.xyz[at].y, c.xyz[at].z), key))
						 return;
					 TCell& cell = cells[key];
					 cell.b += v.b, cell.g += v.g, cell.r += v.r, cell.n += v.n;
					 cell.belief.merge(v.belief);
				 });
	if (i != centres.size()) throw std::logic_error("CDenseSemanticMapper::build: the two passes saw different voxels");
	octreeBuilt.get();
	for (const auto& [key, cell] : cells)
	{
		CSemanticOcTreeNode* node = m.octree->search(key);
		if (!node || !m.octree->isNodeOccupied(node)) continue;
		node->b = static_cast<std::uint8_t>(cell.b / cell.n);
		node->g = static_cast<std::uint8_t>(cell.g / cell.n);
		node->r = static_cast<std::uint8_t>(cell.r / cell.n);
		const auto [label, prob] = cell.belief.best(K);
		node->label = label;
		node->labelProb = static_cast<float>(prob);
	}
	m.octree->updateInnerSemantics();
	m.octree->prune();
	m.buildMs = msSince(t0);
	return m;
}
}  // namespace mrpt_yesslam
