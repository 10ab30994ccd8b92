#pragma once
// Local mapping (ORB-SLAM2's LocalMapping, for RGB-D): for each new keyframe, cull the young map
// points that tracking rarely finds, then run local bundle adjustment in Ceres over the keyframe,
// its covisible keyframes and the points they see, with the other keyframes that see those points
// held fixed (keyframe 0 always fixed: it anchors the map). The class knows nothing of threads;
// CYesSlamSystem runs step() in the caller's thread or in a worker thread ([System] parallel).
#include <mrpt/config/CLoadableOptions.h>

#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/util/ConfigFile.h"

namespace mrpt_yesslam
{
/** What one bundle adjustment did. */
struct TBundleStats
{
	std::size_t keyFrames = 0, fixedKeyFrames = 0, points = 0, observations = 0, outliers = 0;
	double initialCost = 0, finalCost = 0;
};

/** The local mapping stage. */
class CLocalMapper
{
   public:
	/** Section [LocalMapping]. */
	struct TOptions : public mrpt::config::CLoadableOptions
	{
		bool bundleAdjustment = true;
		std::size_t covisibleKeyFrames = 10;  //!< optimised besides the new keyframe
		std::size_t maxFixedKeyFrames = 20;	 //!< other keyframes seeing the points, held fixed
		int iterations = 10;
		/** Depth noise sigma_z = depthNoise x z^2 (m) of the depth residual; 0 = reprojection only. */
		double depthNoise = 0.0025;
		double cullFoundRatio = 0.25;  //!< young points found in fewer than this share of views are culled
		std::size_t cullMinObservations = 2;  //!< young points seen by fewer keyframes are culled
		double scaleFactor = 1.2;  //!< ORB pyramid scale (sigma of an observation = scale ^ octave)

		void loadFromConfigFile(const mrpt::config::CConfigFileBase& source, const std::string& section) override;
		void dumpToTextStream(std::ostream& out) const override;
		/** The keys loadFromConfigFile reads, for validateConfigSection. */
		static std::vector<TConfigKey> configKeys();
	};

	CLocalMapper(const TOptions& opts, CSparseMap& map) : opts_(opts), map_(map) {}

	/** Processes keyframe `kf` (already in the map): culling, then local BA. */
	TBundleStats step(std::size_t kf);
	/** Local bundle adjustment around `kf` alone. */
	TBundleStats bundleAdjust(std::size_t kf);
	const TOptions& options() const { return opts_; }

   private:
	TOptions opts_;
	CSparseMap& map_;
};
}  // namespace mrpt_yesslam
