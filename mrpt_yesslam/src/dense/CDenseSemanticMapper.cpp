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
#include "../util/Deflate.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
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
// A voxel key: three 21-bit signed cell indices (+-10 km at 1 cm).
std::int64_t voxelKey(const cv::Point3f& p, double inv)
{
	auto c = [&](float v) { return (static_cast<std::int64_t>(std::floor(v * inv)) + (1 << 20)) & 0x1FFFFF; };
	return (c(p.x) << 42) | (c(p.y) << 21) | c(p.z);
}

cv::Point3f transform(const mrpt::poses::CPose3D& T, const cv::Point3f& p)
{
	double x, y, z;
	T.composePoint(p.x, p.y, p.z, x, y, z);
	return {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)};
}

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

struct CDenseSemanticMapper::TPackedCloud
{
	struct TPoint
	{
		std::int16_t x, y, z;  //!< keyframe frame, in steps of the mapper's unit_
		std::uint8_t b, g, r;
		TSemLabel label;
		std::uint8_t prob;  //!< labelProb x 255 (0 = no label evidence)
	};
	static_assert(sizeof(TPoint) == 12, "12 bytes a point unpacked");
	static constexpr std::size_t kPlanes =
		11;  //!< bytes a point, planar: x, y, z deltas (low, high), b, g, r, label, prob

	std::size_t size = 0;  //!< points
	/** The points DEFLATEd as planes of bytes, each coordinate as its difference from the point
	 * before (issue 41 item 5: a long run keeps one cloud per keyframe, culled ones included; the
	 * points come in pixel order, so neighbours differ little and a plane's bytes repeat).
	 * About 5 bytes a point instead of 12, exactly the same points back. */
	std::vector<std::uint8_t> bytes;

	static std::shared_ptr<const TPackedCloud> pack(const std::vector<TPoint>& pts)
	{
		const std::size_t n = pts.size();
		std::vector<std::uint8_t> planes(n * kPlanes);
		std::int16_t prev[3] = {0, 0, 0};
		for (std::size_t i = 0; i < n; i++)
		{
			const TPoint& p = pts[i];
			const std::int16_t v[3] = {p.x, p.y, p.z};
			for (int a = 0; a < 3; a++)
			{
				const auto d =
					static_cast<std::uint16_t>(static_cast<std::uint16_t>(v[a]) - static_cast<std::uint16_t>(prev[a]));
				planes[(2 * a) * n + i] = static_cast<std::uint8_t>(d & 0xFF);
				planes[(2 * a + 1) * n + i] = static_cast<std::uint8_t>(d >> 8);
				prev[a] = v[a];
			}
			planes[6 * n + i] = p.b, planes[7 * n + i] = p.g, planes[8 * n + i] = p.r;
			planes[9 * n + i] = p.label, planes[10 * n + i] = p.prob;
		}
		auto c = std::make_shared<TPackedCloud>();
		c->size = n;
		// Level 1: nearly all the packing at little cost in time; higher levels take much longer to save little more
		// (docs/benchmarks.md, "The memory work of 2026-11-28, third round: the dense store packed, the network let
		// go").
		c->bytes = deflateBytes(planes.data(), planes.size(), 1);
		return c;
	}

	/** The points, as packed, into `out` (reused between calls to keep its allocation). */
	void unpack(std::vector<TPoint>& out, std::vector<std::uint8_t>& planes) const
	{
		const std::size_t n = size;
		planes.resize(n * kPlanes);
		// Only this mapper's own packing is ever read (nothing loads it from a file): failing here
		// means memory was corrupted or no decompressor could be had.
		if (!inflateBytes(bytes, planes.data(), planes.size()))
			throw std::runtime_error("dense map: a stored keyframe cloud could not be unpacked (out of memory?)");
		out.resize(n);
		std::uint16_t acc[3] = {0, 0, 0};
		for (std::size_t i = 0; i < n; i++)
		{
			TPoint& p = out[i];
			for (int a = 0; a < 3; a++)
				acc[a] =
					static_cast<std::uint16_t>(acc[a] + (planes[(2 * a) * n + i] | (planes[(2 * a + 1) * n + i] << 8)));
			// (uint16 -> int16 above 32767 wraps, as the packing's uint16 differences assume: GCC and Clang define it
			// so.)
			p.x = static_cast<std::int16_t>(acc[0]), p.y = static_cast<std::int16_t>(acc[1]),
			p.z = static_cast<std::int16_t>(acc[2]);
			p.b = planes[6 * n + i], p.g = planes[7 * n + i], p.r = planes[8 * n + i];
			p.label = planes[9 * n + i], p.prob = planes[10 * n + i];
		}
	}
};

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
