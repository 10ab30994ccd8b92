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

COptionTable CDenseSemanticMapper::TOptions::table()
{
	COptionTable t("DenseMapping");
	t.flag("enabled", enabled,
		   "build the dense labelled cloud and the semantic OctoMap from the keyframes (--no-dense-map: false)");
	t.integer("pixelStep", pixelStep, 1, 16, "back-project every n-th pixel of each row and column");
	t.real("minDepth", minDepth, 0, 100, "nearer depth is ignored, m");
	t.real("maxDepth", maxDepth, 0.1, 100, "farther depth is ignored (and rays end there), m");
	t.real("maxDepthJump", maxDepthJump, 0, 10,
		   "a pixel differing from a neighbour by more than this share of its depth is a flying pixel (left out)");
	t.text("dynamicExclusion", dynamicExclusion,
		   "box: leave out the dynamic mask and the grown box of every dynamic detection; mask: the mask only; none: "
		   "people go into the map (what --no-dynamic-filter sets)",
		   {"box", "mask", "none"});
	t.real("dynamicBoxGrow", dynamicBoxGrow, 0, 1, "box exclusion: share of the box size added on every side");
	t.integer("dynamicHoldKeyFrames", dynamicHoldKeyFrames, 0, 100,
			  "box exclusion: the dynamic boxes of this many previous keyframes are left out too (a person the "
			  "detector misses for a while)");
	t.real("voxelSize", voxelSize, 0.001, 1, "grid of the dense cloud and of label fusion, m");
	t.real("labelProbMin", labelProbMin, 0.5, 1, "p(class) a detection of score 0 gives its pixels (eq. 29)");
	t.real("labelProbMax", labelProbMax, 0.5, 1, "p(class) a detection of score 1 gives its pixels (eq. 29)");
	t.text("labelMethod", labelMethod,
		   "segments: a static object is the smooth-surface segments inside its box (not running on past it); fill: "
		   "the masker's depth flood fill from one seed (the paper's)",
		   {"segments", "fill"});
	t.real("labelDepthRange", labelDepthRange, 0, 100,
		   "fill: label fills never take depth farther than this from their seed's, m (0 = no limit)");
	t.real("segmentNormalAngle", segmentNormalAngle, 1, 90,
		   "segments: neighbours whose normals differ by more degrees are different surfaces");
	t.real("segmentMarginShare", segmentMarginShare, 0, 1,
		   "segments: a segment with more than this share of its pixels in the margin around the box is background");
	t.real("backgroundProb", backgroundProb, 0.01, 0.999, "p(background) of a pixel outside every detection (eq. 29)");
	t.integer("outlierNeighbours", outlierNeighbours, 0, 100,
			  "statistical outlier removal: neighbours per point (0 = off)");
	t.real("outlierStdDev", outlierStdDev, 0, 100,
		   "remove points whose mean neighbour distance exceeds the mean by this many standard deviations");
	t.real("octomapResolution", octomapResolution, 0.005, 10, "OctoMap voxel size, m (--octomap-resolution)");
	t.real("probHit", probHit, 0.5, 1, "OctoMap: occupancy probability of a ray's end");
	t.real("probMiss", probMiss, 0, 0.5, "OctoMap: occupancy probability of the cells a ray passes");
	t.real("occupancyThreshold", occupancyThreshold, 0.55, 0.999,
		   "OctoMap: occupied above this probability (0.8: two keyframes' hits; above 0.51, what a seen but "
		   "unconfirmed surface keeps)");
	t.real("clearMargin", clearMargin, 0, 1,
		   "OctoMap: a ray marks space free only up to this far before the surface it measured, m (depth noise, "
		   "thinning)");
	t.integer("minObservations", minObservations, 1, 1000, "dense cloud: keyframes that must see a voxel");
	t.count("buildSlabPoints", buildSlabPoints, 1000, std::size_t{1} << 34,
			"final build: stored points sorted by voxel at a time (32 bytes each; fewer = less memory, more passes; "
			"the same map)");
	t.count("queue", queue, 1, 1000, "parallel mode: keyframes waiting for the dense stage before tracking waits");
	t.real("culledCloudsMB", culledCloudsMB, 0, 1e6,
		   "MB the stored clouds may take before the clouds of culled keyframes are dropped, oldest first (the map's "
		   "own keyframes' clouds always stay; 0 = as soon as culled)");
	return t;
}

namespace
{
CDynamicObjectMasker::TOptions labelFillOptions(CDynamicObjectMasker::TOptions m, double depthRange)
{
	m.maxDepthRange = depthRange;
	// A failed fill labels nothing (a whole box would give the background around a monitor its
	// class); labels are not grown (the dynamic mask's margin is for features on silhouettes).
	m.fallbackToBox = false;
	m.dilatePixels = 0;
	m.holdFrames = 0;
	return m;
}
}  // namespace

cv::Vec3b labelColour(TSemLabel label)
{
	if (label == 0) return {170, 170, 170};
	// 20 well separated colours (Kelly's list, BGR) cycled over the labels: neighbouring COCO
	// classes (desk 60, tv 62, keyboard 66) get different ones.
	static const cv::Vec3b kPalette[20] = {
		{0, 179, 255}, {117, 62, 128},  {0, 104, 255}, {204, 161, 166}, {34, 0, 193},  {98, 189, 206}, {118, 112, 129},
		{52, 125, 0},  {142, 118, 246}, {117, 83, 0},  {122, 117, 255}, {151, 55, 83}, {0, 142, 255},  {126, 40, 179},
		{0, 200, 244}, {24, 16, 127},   {0, 170, 147}, {21, 51, 89},    {19, 58, 241}, {40, 44, 35}};
	return kPalette[(label - 1) % 20];
}

namespace
{
CObjectSegmenter::TParams segmenterParams(const CDenseSemanticMapper::TOptions& o)
{
	CObjectSegmenter::TParams p;
	p.maxNormalAngleDeg = o.segmentNormalAngle;
	p.maxMarginShare = o.segmentMarginShare;
	return p;
}
}  // namespace

CDenseSemanticMapper::CDenseSemanticMapper(const TOptions& o, const CDynamicObjectMasker::TOptions& masker,
										   int numClasses)
	: opts_(o),
	  masker_(labelFillOptions(masker, o.labelDepthRange)),
	  segmenter_(segmenterParams(o)),
	  numClasses_(std::max(1, numClasses)),
	  // 1 mm steps reach 32 m: enough for any depth camera; farther maxDepth coarsens the step.
	  unit_(std::max(0.001, o.maxDepth * 1.01 / 32000))
{
	if (o.labelMethod != "segments" && o.labelMethod != "fill")
		throw InputError("", "[DenseMapping] labelMethod must be segments or fill, got '" + o.labelMethod + "'");
	if (!(o.maxDepth > o.minDepth)) throw InputError("", "[DenseMapping] maxDepth must exceed minDepth");
	if (!(o.labelProbMax >= o.labelProbMin))
		throw InputError("", "[DenseMapping] labelProbMax must be >= labelProbMin");
	if (o.dynamicExclusion != "box" && o.dynamicExclusion != "mask" && o.dynamicExclusion != "none")
		throw InputError("",
						 "[DenseMapping] dynamicExclusion must be box, mask or none, got '" + o.dynamicExclusion + "'");
	if (!(o.octomapResolution > 0)) throw InputError("", "[DenseMapping] octomapResolution must be > 0");
	// The octree is built from the filtered cloud: finer than its grid it holds no more detail, only more nodes, slower
	// and larger to build, with fewer cells occupied.
	if (o.octomapResolution < o.voxelSize - 1e-12)
	{
		char b[320];
		std::snprintf(
			b, sizeof(b),
			"[DenseMapping] octomapResolution (--octomap-resolution) %.3g m is finer than the dense cloud's voxelSize "
			"%.3g m it is built "
			"from: it would add no detail, only time and memory; use %.3g m or coarser (or a finer voxelSize)",
			o.octomapResolution, o.voxelSize, o.voxelSize);
		throw InputError("", b);
	}
	if (numClasses_ + 1 > 256)
		throw InputError("", "the dense map stores labels in one byte: at most 255 detector classes");
}

TObjectLabels CDenseSemanticMapper::labelPixels(const cv::Mat& depth, const mrpt::img::TCamera& camera,
												const std::vector<TDetection>& objects) const
{
	if (opts_.labelMethod == "segments") return segmenter_.segment(depth, camera, objects);
	const TDynamicMask seg = masker_.segmentAll(depth, objects);
	TObjectLabels r;
	r.instance = seg.instanceLabels;
	r.unknown = cv::Mat::zeros(depth.size(), CV_8U);
	return r;
}

TKeyFrameCloud CDenseSemanticMapper::keyFrameCloud(const TFrame& f) const
{
	return keyFrameCloud(f, {});
}

TKeyFrameCloud CDenseSemanticMapper::keyFrameCloud(const TFrame& f, const std::vector<cv::Rect2f>& heldBoxes) const
{
	TKeyFrameCloud c;
	if (!f.images) return c;
	const cv::Mat& depth = f.images->depth;
	const cv::Mat& bgr = f.images->bgr;
	if (depth.empty() || depth.type() != CV_32F || bgr.size() != depth.size()) return c;
	const int W = depth.cols, H = depth.rows;

	// Per-pixel labels: the fill of every detection that is not dynamic.
	std::vector<TDetection> objects;
	for (const auto& d : f.detections)
		if (!d.dynamic) objects.push_back(d);
	// Larger boxes first: a keyboard's fill is drawn over the desk's that may have run onto it.
	std::stable_sort(objects.begin(), objects.end(),
					 [](const TDetection& a, const TDetection& b) { return a.box.area() > b.box.area(); });
	const TObjectLabels seg = labelPixels(depth, f.camera, objects);

	// What never goes in: tracking's dynamic mask, and (box) every dynamic detection's grown box.
	cv::Mat excluded = f.images->dynamicMask.empty() || opts_.dynamicExclusion == "none"
						   ? cv::Mat::zeros(depth.size(), CV_8U)
						   : f.images->dynamicMask.clone();
	if (opts_.dynamicExclusion == "box")
	{
		std::vector<cv::Rect2f> boxes = heldBoxes;
		for (const auto& d : f.detections)
			if (d.dynamic) boxes.push_back(d.box);
		for (const auto& box : boxes)
		{
			const cv::Rect r = coveringRect(box, opts_.dynamicBoxGrow, 1, cv::Rect(0, 0, W, H));
			if (r.area() > 0) excluded(r).setTo(255);
		}
	}

	// Undistorted pixel positions of the grid (only when the camera has distortion).
	const CPinholeCamera K(f.camera);
	const int step = opts_.pixelStep;
	std::vector<cv::Point2f> grid;
	for (int v = 0; v < H; v += step)
		for (int u = 0; u < W; u += step) grid.emplace_back(static_cast<float>(u), static_cast<float>(v));
	std::vector<cv::Point2f> undist = grid;
	if (K.distorted()) K.undistort(undist);
	const double fx = f.camera.fx(), fy = f.camera.fy(), cx = f.camera.cx(), cy = f.camera.cy();

	const double inv = 1.0 / opts_.voxelSize;
	std::unordered_map<std::int64_t, std::size_t> seen;
	seen.reserve(grid.size() / 2);
	const float jump = static_cast<float>(opts_.maxDepthJump);
	for (std::size_t i = 0; i < grid.size(); i++)
	{
		const int u = static_cast<int>(grid[i].x), v = static_cast<int>(grid[i].y);
		const float z = depth.at<float>(v, u);
		if (!(z >= opts_.minDepth && z <= opts_.maxDepth)) continue;
		if (excluded.at<uchar>(v, u))
		{
			c.dynamicPixelsLeftOut++;
			continue;
		}
		if (jump > 0)
		{
			bool edge = false;
			static const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
			for (int k = 0; k < 4 && !edge; k++)
			{
				const int x = u + du[k], y = v + dv[k];
				if (x < 0 || y < 0 || x >= W || y >= H) continue;
				const float zn = depth.at<float>(y, x);
				edge = zn > 0 && std::abs(zn - z) > jump * z;
			}
			if (edge) continue;
		}
		const cv::Point3f p(static_cast<float>((undist[i].x - cx) * z / fx),
							static_cast<float>((undist[i].y - cy) * z / fy), z);  // eq. 25
		if (!seen.emplace(voxelKey(p, inv), c.xyz.size()).second) continue;       // thinned: one point per voxel
		c.xyz.push_back(p);
		c.bgr.push_back(bgr.at<cv::Vec3b>(v, u));
		const int inst = seg.instance.at<std::uint16_t>(v, u) - 1;
		if (inst >= 0 && inst < static_cast<int>(objects.size()))
		{
			const TDetection& d = objects[static_cast<std::size_t>(inst)];
			c.label.push_back(static_cast<TSemLabel>(std::min(d.classId + 1, 255)));
			c.labelProb.push_back(
				static_cast<float>(opts_.labelProbMin + (opts_.labelProbMax - opts_.labelProbMin) *
															std::clamp(static_cast<double>(d.score), 0.0, 1.0)));
		}
		else if (seg.unknown.at<uchar>(v, u))
		{
			c.label.push_back(0);  // inside a box that found no object: no label evidence
			c.labelProb.push_back(0);
		}
		else
		{
			c.label.push_back(0);
			c.labelProb.push_back(static_cast<float>(opts_.backgroundProb));
		}
	}
	return c;
}

void CDenseSemanticMapper::addKeyFrame(TKeyFrameId id, const TFrame& frame)
{
	if (!frame.images) return;
	std::vector<cv::Rect2f> held;
	{
		std::lock_guard<std::mutex> lk(mtx_);
		for (const auto& boxes : recentDynamic_) held.insert(held.end(), boxes.begin(), boxes.end());
	}
	TKeyFrameCloud c = keyFrameCloud(frame, held);
	std::vector<cv::Rect2f> mine;
	for (const auto& d : frame.detections)
		if (d.dynamic) mine.push_back(d.box);
	{
		std::lock_guard<std::mutex> lk(mtx_);
		recentDynamic_.push_back(std::move(mine));
		while (recentDynamic_.size() > static_cast<std::size_t>(opts_.dynamicHoldKeyFrames)) recentDynamic_.pop_front();
	}
	setKeyFrameCloud(id, std::move(c));
}

void CDenseSemanticMapper::setKeyFrameCloud(TKeyFrameId id, TKeyFrameCloud cloud)
{
	std::vector<TPackedCloud::TPoint> points;
	points.reserve(cloud.xyz.size());
	const double inv = 1.0 / unit_;
	auto q = [&](float v) { return static_cast<std::int16_t>(std::clamp(std::lround(v * inv), -32767L, 32767L)); };
	for (std::size_t i = 0; i < cloud.xyz.size(); i++)
	{
		const auto& x = cloud.xyz[i];
		const auto& c = cloud.bgr[i];
		const float pr = cloud.labelProb[i];
		// A probability that quantises to 0 still is evidence: at least 1.
		const auto prob = static_cast<std::uint8_t>(pr > 0 ? std::clamp(std::lround(pr * 255), 1L, 255L) : 0);
		points.push_back({q(x.x), q(x.y), q(x.z), c[0], c[1], c[2], cloud.label[i], prob});
	}
	auto p = TPackedCloud::pack(points);
	std::lock_guard<std::mutex> lk(mtx_);
	auto& slot = clouds_[id];
	if (slot) storedBytes_ -= sizeof(TPackedCloud) + slot->bytes.capacity();
	storedBytes_ += sizeof(TPackedCloud) + p->bytes.capacity();
	slot = std::move(p);
	dropCulledOverBudget();
}

void CDenseSemanticMapper::keyFramesCulled(const std::vector<TKeyFrameId>& ids)
{
	std::lock_guard<std::mutex> lk(mtx_);
	culled_.insert(ids.begin(), ids.end());
	dropCulledOverBudget();
}

void CDenseSemanticMapper::dropCulledOverBudget()
{
	const double budget = opts_.culledCloudsMB * 1e6;  // as stats.json's stored_mb
	// A culled keyframe whose cloud has not come yet (the dense stage's queue) stays marked.
	for (auto it = culled_.begin(); it != culled_.end() && static_cast<double>(storedBytes_) > budget;)
	{
		const auto c = clouds_.find(*it);
		if (c == clouds_.end())
		{
			++it;
			continue;
		}
		storedBytes_ -= sizeof(TPackedCloud) + c->second->bytes.capacity();
		clouds_.erase(c);
		it = culled_.erase(it);
		dropped_++;
	}
}

std::size_t CDenseSemanticMapper::droppedClouds() const
{
	std::lock_guard<std::mutex> lk(mtx_);
	return dropped_;
}

void CDenseSemanticMapper::setPrior(const CSemanticOcTree& tree)
{
	std::string bytes = tree.otBytes();
	std::lock_guard<std::mutex> lk(mtx_);
	prior_ = std::move(bytes);
}

std::size_t CDenseSemanticMapper::storedBytes() const
{
	std::lock_guard<std::mutex> lk(mtx_);
	return storedBytes_;
}

std::size_t CDenseSemanticMapper::numKeyFrames() const
{
	std::lock_guard<std::mutex> lk(mtx_);
	return clouds_.size();
}

std::size_t CDenseSemanticMapper::numStoredPoints() const
{
	std::lock_guard<std::mutex> lk(mtx_);
	std::size_t n = 0;
	for (const auto& [id, c] : clouds_) n += c->size;
	return n;
}

}  // namespace mrpt_yesslam
