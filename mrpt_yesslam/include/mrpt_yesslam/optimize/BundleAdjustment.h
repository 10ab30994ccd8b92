#pragma once
// Bundle adjustment of a window copied out of the map (paper eq. 24), shared by local mapping (a
// keyframe and its covisible keyframes) and loop closing (the whole map, ORB-SLAM2's global BA):
// RGB-D reprojection + depth residuals in Ceres with a Huber loss, then the observations still
// outside the chi-square 95 % bound listed as outliers. The caller writes the result back.
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "mrpt_yesslam/geometry/DepthNoise.h"
#include "mrpt_yesslam/data/CSparseMap.h"

namespace mrpt_yesslam
{
/** What one bundle adjustment did. */
struct TBundleStats
{
	std::size_t keyFrames = 0, fixedKeyFrames = 0, points = 0, observations = 0, outliers = 0;
	/** Keyframes of the window held at their pose: too few of their points seen by another window
	 * keyframe to say where they are (TBundleSolveOptions::minSharedObservations). */
	std::size_t heldKeyFrames = 0;
	double initialCost = 0, finalCost = 0;
	bool applied = false;    //!< false: the map was corrected meanwhile and the result was dropped
	bool cancelled = false;  //!< stopped early by TBundleSolveOptions::cancelled (the result is stale)
	int iterations = 0;      //!< Ceres iterations run
};

/** How to solve. */
struct TBundleSolveOptions
{
	double scaleFactor = 1.2;  //!< ORB pyramid: pixel sigma = scale ^ octave
	/** The sensor's depth noise: an observation's sigma_z = depthNoise.sigma(z, scale^octave); a
	 * depth beyond its farDepth is no residual, and a point no keyframe of the window measures
	 * nearer keeps its position (as a point without depth does). */
	TDepthNoise depthNoise;
	int iterations = 10;
	/** A keyframe with fewer observations of points that another keyframe of the window also
	 * observes is held at its pose: its other points move with it, so nothing says where it is, and
	 * the solve let it drift (a keyframe made from a frame tracked against the last frame's depth
	 * points alone linked 2 map points; local BA moved it 28 cm and 4 degrees, and the frames
	 * anchored to it with it: crowd seed 3, rolling shutter, 6.3 mm ATE online, 17.4 mm final). */
	std::size_t minSharedObservations = 20;
	/** Sparse Schur for many cameras (global BA); dense Schur is faster for a local window. */
	bool sparse = false;
	int threads = 1;
	/** Asked after every iteration; true stops the solve (a global BA whose window a newer
	 * correction has made stale: its result would be refused, so it stops instead of running on). */
	std::function<bool()> cancelled;
};

/** The optimised window. */
struct TBundleSolution
{
	std::map<TKeyFrameId, mrpt::poses::CPose3D> poses;  //!< the window's optimised keyframes
	std::vector<mrpt::math::TPoint3D> positions;        //!< per window point
	std::vector<std::pair<TPointId, TKeyFrameId>> outliers;
	TBundleStats stats;
};

/** Optimises the window's keyframes (not the fixed ones) and points. */
TBundleSolution solveBundle(const TBundleWindow& w, const TBundleSolveOptions& o);
}  // namespace mrpt_yesslam
