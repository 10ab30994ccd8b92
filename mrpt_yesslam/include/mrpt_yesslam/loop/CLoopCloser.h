#pragma once
// Loop correction (paper eq. 24, ORB-SLAM2's LoopClosing::CorrectLoop and RunGlobalBundleAdjustment
// with SE3 for RGB-D):
// 1. the current keyframe and its covisible keyframes are moved rigidly to where the verified loop
//    transform puts the current keyframe, with the points they observe;
// 2. loop fusion: the loop place's map points, projected into those keyframes, replace the
//    duplicates tracking created on the way back (or are added as observations);
// 3. the essential graph (spanning tree, covisibility edges of weight >= 100, loop edges) is
//    optimised in Ceres with the loop keyframe fixed: edges measured on the poses before the
//    correction, except the new loop links, which carry the corrected ones, so the error spreads
//    along the loop; every keyframe and point then follows;
// 4. global bundle adjustment of every keyframe and point (the caller runs it, in the background
//    in parallel mode); keyframes and points created meanwhile follow their ancestors, and a result
//    computed before another correction is dropped.
#include <functional>
#include <memory>

#include "mrpt_yesslam/geometry/DepthNoise.h"
#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/loop/CLoopDetector.h"
#include "mrpt_yesslam/optimize/BundleAdjustment.h"
#include "mrpt_yesslam/util/CWriterFirstMutex.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** What one correction did. */
struct TLoopCorrection
{
	std::size_t groupKeyFrames = 0;  //!< keyframes moved with the current one
	std::size_t fused = 0;           //!< observations added and duplicates fused
	std::size_t loopLinks = 0;       //!< new covisibility links between the two sides of the loop
	std::size_t graphKeyFrames = 0, graphEdges = 0;
	double correctionMetres = 0;  //!< how far the current keyframe moved
	double poseGraphMs = 0;
};

/** The loop-closing stage. */
class CLoopCloser
{
   public:
	/** Section [LoopClosing]: detection (CLoopDetector) and these. */
	struct TOptions : public TTableOptions<TOptions>
	{
		CLoopDetector::TOptions detection;
		int essentialWeight = 100;           //!< covisibility edges of the essential graph (ORB-SLAM2: 100)
		int poseGraphIterations = 20;        //!< ORB-SLAM2: 20
		bool globalBundleAdjustment = true;  //!< global BA after each correction
		int globalIterations = 10;           //!< ORB-SLAM2: 10
		double fuseRadius = 4;  //!< loop fusion search radius, pixels at level 0 (ORB-SLAM2's SearchAndFuse: 4)

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	/** `scaleFactor`: the ORB pyramid's; `depthNoise`: the sensor's ([Camera]: global BA's depth
	 * term, loop fusion's gate). */
	CLoopCloser(const TOptions& opts, CSparseMap& map, double scaleFactor = 1.2,
				const TDepthNoise& depthNoise = TDepthNoise());

	/** Corrects the map for a verified loop (steps 1-3 above). Where the current keyframe goes is
	 * the matched keyframe's pose now times the verified relative pose (TLoop::relative), not the
	 * pose detection computed: a local or global BA between the two moves the matched keyframe.
	 * groupKeyFrames = 0: nothing was applied (a keyframe of the pair is gone). */
	TLoopCorrection correct(const TLoop& loop);
	/** Global BA of the whole map (step 4); `applied` says whether it was written back. The solve
	 * runs unlocked; the write-back holds `writeLock` (the system's map-update lock) when given, so
	 * that it never lands between a loop correction's reading of the poses and its writing. */
	TBundleStats globalBundleAdjust(CWriterFirstMutex* writeLock = nullptr);
	const TOptions& options() const { return opts_; }
	/** Test only: `hook` runs in each global BA after its window was read, before the solve (where
	 * a correction from elsewhere makes the solve stale). Set before the first keyframe. */
	void setGlobalBundleHook(std::function<void()> hook) { gbaHook_ = std::move(hook); }

   private:
	std::function<void()> gbaHook_;  //!< setGlobalBundleHook
	TOptions opts_;
	CSparseMap& map_;
	double scaleFactor_;
	TDepthNoise depthNoise_;
};
}  // namespace mrpt_yesslam
