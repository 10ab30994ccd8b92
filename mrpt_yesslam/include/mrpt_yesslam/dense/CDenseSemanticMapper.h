#pragma once
// The dense semantic map (paper section 2.6, eq. 25-29): a labelled point cloud and a semantic
// OctoMap built from the keyframes' depth and colour, without the people who walked through.
//
// Per keyframe (addKeyFrame, on the dense-mapping stage): every static object's detection is cut
// out of its box (CObjectSegmenter: smooth-surface segments inside the box; or, as the paper, the
// masker's depth flood fill, CDynamicObjectMasker::segmentAll), giving per-pixel labels;
// the depth is back-projected (eq. 25) on a pixel grid, leaving out what tracking masked as
// dynamic (held objects included) and, beyond the paper, the whole box of every dynamic detection
// grown a little (a flood fill leaves 7-14 % of a person's pixels outside its mask, docs/benchmarks.md masking
// table; any of them in the map is a ghost) and depth-edge "flying pixels"; the cloud is thinned
// on a voxel grid and stored in the keyframe's own coordinates.
//
// The map (build) is made from those clouds with the keyframes' poses at that moment (eq. 26), so
// local BA, culling (a culled keyframe's cloud follows its parent) and loop correction all move
// it, as dense ORB-SLAM2 forks rebuild their clouds after a loop. Labels are fused per voxel over
// all keyframes (eq. 27-29, TLabelBelief); the fused cloud is filtered (voxel grid, statistical
// outliers with MRPT's KD-tree, as PCL's StatisticalOutlierRemoval); the octree gets each
// keyframe's points by ray casting from its camera, so space a person walked through is cleared.
#include <mrpt/poses/CPose3D.h>

#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "mrpt_yesslam/data/CMapPoint.h"
#include "mrpt_yesslam/data/TFrame.h"
#include "mrpt_yesslam/dense/CObjectSegmenter.h"
#include "mrpt_yesslam/dense/CSemanticOcTree.h"
#include "mrpt_yesslam/dense/SemanticFusion.h"
#include "mrpt_yesslam/dynamic/CDynamicObjectMasker.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** One keyframe's points in its camera frame. */
struct TKeyFrameCloud
{
	std::vector<cv::Point3f> xyz;
	std::vector<cv::Vec3b> bgr;
	std::vector<TSemLabel> label;          //!< 0 = background, c + 1 = class c
	std::vector<float> labelProb;          //!< p^(label | pixel) of the measurement model; 0 = no label evidence
	std::size_t dynamicPixelsLeftOut = 0;  //!< grid pixels with depth not inserted as dynamic
};

/** The fused, filtered cloud (world frame = the SLAM map's). */
struct TDenseCloud
{
	std::vector<cv::Point3f> xyz;
	std::vector<cv::Vec3b> bgr;
	std::vector<TSemLabel> label;             //!< fused (most likely) label
	std::vector<float> labelProb;             //!< its posterior probability
	std::vector<std::uint32_t> observations;  //!< keyframes whose points were fused into the voxel

	std::size_t size() const { return xyz.size(); }
};

/** What build() made. */
struct TDenseMap
{
	TDenseCloud cloud;
	std::unique_ptr<CSemanticOcTree> octree;
	std::size_t keyFrames = 0;  //!< clouds used
	std::size_t voxelsBeforeFilter = 0, outliersRemoved = 0;
	double buildMs = 0;
	/** The octree started from the prior map (setPrior); false also when it had another resolution. */
	bool priorMerged = false;
};

/** The dense mapper. Thread-safe: addKeyFrame and build may run on different threads. */
class CDenseSemanticMapper
{
   public:
	/** Section [DenseMapping]. */
	struct TOptions : public TTableOptions<TOptions>
	{
		bool enabled = true;    //!< build the dense map and OctoMap (off: --no-dense-map)
		int pixelStep = 2;      //!< back-project every n-th pixel of each row and column
		double minDepth = 0.3;  //!< m: nearer depth is ignored
		double maxDepth = 4.0;  //!< m: farther depth is ignored (also the rays' length)
		/** A pixel whose 4 neighbours differ from it by more than this share of its depth lies on a
		 * depth edge (a "flying pixel" mixing foreground and background) and is left out. */
		double maxDepthJump = 0.04;
		/** box: the whole box of every dynamic detection is left out, grown by dynamicBoxGrow, as
		 * well as the dynamic mask; mask: only the mask, as tracking uses it; none: nothing is left
		 * out (the system sets it with [System] dynamicFilter = false: the baseline maps people). */
		std::string dynamicExclusion = "box";
		double dynamicBoxGrow = 0.1;  //!< share of the box size added on every side
		/** box: the dynamic boxes of this many previous keyframes are left out as well. The masker
		 * holds a missed person's box for a few frames only; a person the detector misses for
		 * longer (or a sitting person's arm) would otherwise go into the map where it stays. */
		int dynamicHoldKeyFrames = 2;
		double voxelSize = 0.02;  //!< m: grid of the dense cloud (and of label fusion)
		/** Measurement model (eq. 29): a pixel inside the fill of a detection with score s says "its
		 * class" with probability labelProbMin + (labelProbMax - labelProbMin) * s. */
		double labelProbMin = 0.55, labelProbMax = 0.9;
		/** segments: static objects are the smooth-surface segments inside their box
		 * (CObjectSegmenter); fill: the masker's depth flood fill from one seed (the paper's). */
		std::string labelMethod = "segments";
		/** fill: the label fills never take depth farther than this from their seed's, m
		 * ([DynamicMask] maxDepthRange plays this part for people). */
		double labelDepthRange = 0.5;
		double segmentNormalAngle = 30;  //!< segments: degrees between neighbours' normals that still make one surface
		double segmentMarginShare = 0.25;  //!< segments: a segment with more of its pixels around the box is background
		double backgroundProb = 0.6;       //!< a pixel outside every detection says "background" with this probability
		int outlierNeighbours = 12;        //!< statistical outlier removal: neighbours (0 = off)
		double outlierStdDev = 2.0;        //!< removes points whose mean neighbour distance exceeds mean + this * std
		double octomapResolution = 0.05;   //!< m (--octomap-resolution)
		double probHit = 0.7, probMiss = 0.4;  //!< OctoMap's sensor model (its defaults)
		/** A cell is occupied above this probability. OctoMap's default 0.5 makes one keyframe's
		 * hit enough; 0.8 needs two keyframes (with probHit 0.7), so that a person's body, which
		 * is somewhere else at the next keyframe, never becomes an obstacle even where the mask
		 * leaked and no later ray passes to clear it (beyond the paper). */
		double occupancyThreshold = 0.8;
		/** A ray marks space free only up to this far (m) before the surface point it ends at
		 * (CSemanticOcTree::insertScan): depth noise and the cloud's voxelSize thinning put a
		 * surface within about a voxel of where the kept point says. */
		double clearMargin = 0.05;
		/** Dense cloud: a voxel must hold points of this many keyframes (the same reason). */
		int minObservations = 2;
		/** The final build sorts the stored points by voxel this many at a time (32 bytes each),
		 * whole x columns of voxels per pass: less memory, more passes over the clouds; the map is
		 * the same whatever it is. */
		std::size_t buildSlabPoints = std::size_t{1} << 18;
		std::size_t queue = 4;  //!< parallel: keyframes waiting for the dense stage before tracking waits
		/** MB the stored clouds may take before the clouds of keyframes local mapping culled are
		 * dropped, oldest first (they are redundant views; the map's own keyframes' clouds always
		 * stay), so that a long run in one place keeps its memory and its final build bounded. */
		double culledCloudsMB = 16;

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	/** `masker` configures the label fills (its fallback to whole boxes is turned off: a failed
	 * fill labels nothing rather than the background around the object). `numClasses`: the
	 * detector's class count. Throws InputError for invalid options. */
	CDenseSemanticMapper(const TOptions& opts, const CDynamicObjectMasker::TOptions& masker, int numClasses);

	/** Per-pixel labels of the static objects `objects` (larger boxes first) on `depth`, by
	 * labelMethod: instance = index into `objects` + 1. */
	TObjectLabels labelPixels(const cv::Mat& depth, const mrpt::img::TCamera& camera,
							  const std::vector<TDetection>& objects) const;
	/** The cloud of one keyframe from its frame's images (TFrame::images; ignored without them).
	 * Keyframes come in order (dynamicHoldKeyFrames looks back at the previous ones). */
	void addKeyFrame(TKeyFrameId id, const TFrame& frame);
	/** The cloud of one keyframe, made from explicit images (the work of addKeyFrame). */
	TKeyFrameCloud keyFrameCloud(const TFrame& frame) const;
	/** The same, also leaving out `heldBoxes` (dynamic boxes of earlier keyframes, grown alike). */
	TKeyFrameCloud keyFrameCloud(const TFrame& frame, const std::vector<cv::Rect2f>& heldBoxes) const;
	/** Stores a cloud for keyframe `id` (tests and addKeyFrame). */
	void setKeyFrameCloud(TKeyFrameId id, TKeyFrameCloud cloud);
	/** Local mapping culled these keyframes: their clouds (now or when they come) may be dropped
	 * once the store is over culledCloudsMB. */
	void keyFramesCulled(const std::vector<TKeyFrameId>& ids);
	/** Clouds of culled keyframes dropped so far (culledCloudsMB). */
	std::size_t droppedClouds() const;

	/** An earlier run's semantic OctoMap (a loaded map's) that build() starts the octree from, so
	 * that this run's keyframes update it: what they see replaces it (space now free is cleared,
	 * labels seen again are re-fused), the rest is kept. Used only at the same resolution. */
	void setPrior(const CSemanticOcTree& tree);
	/** The fused, filtered cloud and the octree, with each keyframe placed by `poseOf(id)` (T_w_c). */
	TDenseMap build(const std::function<mrpt::poses::CPose3D(TKeyFrameId)>& poseOf) const;
	/** Only the world cloud of every keyframe, unfused (tests of re-placing; every `step`-th point
	 * for finding the floor). */
	std::vector<cv::Point3f> worldPoints(const std::function<mrpt::poses::CPose3D(TKeyFrameId)>& poseOf,
										 std::size_t step = 1) const;

	std::size_t numKeyFrames() const;
	/** Stored points over all keyframes (their memory: storedBytes()). */
	std::size_t numStoredPoints() const;
	/** Memory the stored clouds take. */
	std::size_t storedBytes() const;
	/** Labels: background + the detector's classes. */
	int numLabels() const { return numClasses_ + 1; }
	const TOptions& options() const { return opts_; }

   private:
	TOptions opts_;
	CDynamicObjectMasker masker_;  //!< segmentAll only (const): labelMethod fill
	CObjectSegmenter segmenter_;   //!< labelMethod segments
	int numClasses_;
	/** A keyframe's cloud as stored: per point a position in steps of unit_, colour, label and
	 * quantised probability (12 bytes), DEFLATEd to about 5 bytes, not TKeyFrameCloud's 20 plus
	 * growth slack: a long run keeps one per keyframe, culled ones included. */
	struct TPackedCloud;
	double unit_;  //!< m per stored coordinate step
	mutable std::mutex mtx_;
	std::map<TKeyFrameId, std::shared_ptr<const TPackedCloud>> clouds_;
	std::deque<std::vector<cv::Rect2f>> recentDynamic_;  //!< dynamic boxes of the last keyframes added
	std::string prior_;  //!< setPrior's tree as .ot bytes (each build reads its own copy; the tree cannot be copied)
	std::set<TKeyFrameId> culled_;  //!< culled keyframes whose clouds may go, oldest first (guarded by mtx_)
	std::size_t storedBytes_ = 0;   //!< what clouds_ takes (guarded by mtx_)
	std::size_t dropped_ = 0;       //!< clouds dropped by culledCloudsMB (guarded by mtx_)
	/** Drops culled keyframes' clouds, oldest first, while the store is over culledCloudsMB (mtx_ held). */
	void dropCulledOverBudget();
};

/** A colour per label for pictures (background grey, classes from a fixed palette). */
cv::Vec3b labelColour(TSemLabel label);
}  // namespace mrpt_yesslam
