#pragma once
// Local mapping (ORB-SLAM2's LocalMapping, for RGB-D): for each new keyframe, cull the young map
// points that tracking rarely finds, fuse the duplicates the new keyframe created with the points of
// its neighbours (ORB-SLAM2's SearchInNeighbors: a place seen again must not get a second copy of
// its points), run local bundle adjustment in Ceres over the keyframe, its
// covisible keyframes and the points they see (the other keyframes that see those points held
// fixed; the first keyframe always fixed: it anchors the map), then erase the covisible keyframes
// that have become redundant (ORB-SLAM2's KeyFrameCulling), so that a camera that keeps revisiting
// a known room does not grow the map for ever. The class knows nothing of threads; CYesSlamSystem
// runs step() in the caller's thread or on its mapping stage thread ([System] parallel).
#include <mrpt/config/CLoadableOptions.h>

#include "mrpt_yesslam/geometry/DepthNoise.h"
#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/optimize/BundleAdjustment.h"
#include "mrpt_yesslam/optimize/PointFusion.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** What one local-mapping step did. */
struct TMappingStats
{
	std::size_t culledPoints = 0;
	std::size_t fused = 0;                     //!< observations added and duplicates fused with the neighbours
	std::vector<TKeyFrameId> erasedKeyFrames;  //!< redundant keyframes culled
	TBundleStats bundle;
};

/** The local mapping stage. */
class CLocalMapper
{
   public:
	/** Section [LocalMapping]. */
	struct TOptions : public TTableOptions<TOptions>
	{
		bool bundleAdjustment = true;
		std::size_t covisibleKeyFrames = 10;  //!< optimised besides the new keyframe
		std::size_t maxFixedKeyFrames = 20;   //!< other keyframes seeing the points, held fixed
		int iterations = 10;
		double cullFoundRatio = 0.25;         //!< young points found in fewer than this share of views are culled
		std::size_t cullMinObservations = 2;  //!< young points seen by fewer keyframes are culled
		/** Neighbours searched for duplicates (ORB-SLAM2, RGB-D: 10); 0 = no fusion. Off by default:
		 * measured on unseen yesslam-sim sequences it halves the map points but raised the ATE by
		 * 4-22 % (docs/benchmarks.md), so it stays an option until the fused points' descriptors and positions
		 * are refreshed as ORB-SLAM2 does. */
		std::size_t fuseKeyFrames = 0;
		double fuseRadius = 3;        //!< pixels at level 0 (x scale^octave), ORB-SLAM2's Fuse
		int fuseMaxHamming = 50;      //!< ORB-SLAM2's TH_LOW
		bool keyFrameCulling = true;  //!< erase redundant keyframes (ORB-SLAM2's KeyFrameCulling)
		double redundantRatio = 0.9;  //!< a keyframe goes when more than this share of its close points ...
		std::size_t redundantObservers =
			3;  //!< ... is seen by at least this many other keyframes at the same or finer scale

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	/** `scaleFactor`: the ORB pyramid's ([ORB] scaleFactor; sigma of an observation = scale ^ octave);
	 * `maxDepth`: tracking's, the depth up to which points count as close for keyframe culling;
	 * `depthNoise`: the sensor's ([Camera]), BA's depth term and fusion's depth gate. */
	CLocalMapper(const TOptions& opts, CSparseMap& map, double scaleFactor = 1.2, double maxDepth = 4.0,
				 const TDepthNoise& depthNoise = TDepthNoise());

	/** Processes keyframe `kf` (already in the map): point culling, local BA, keyframe culling. */
	TMappingStats step(TKeyFrameId kf);
	/** Fusion of `kf`'s points with its neighbours' alone; returns what fuse() changed. */
	std::size_t fuseWithNeighbours(TKeyFrameId kf);
	/** Local bundle adjustment around `kf` alone. */
	TBundleStats bundleAdjust(TKeyFrameId kf);
	const TOptions& options() const { return opts_; }

   private:
	TOptions opts_;
	CSparseMap& map_;
	double scaleFactor_, maxDepth_;
	TDepthNoise noise_;  //!< the sensor's depth noise ([Camera])
};
}  // namespace mrpt_yesslam
