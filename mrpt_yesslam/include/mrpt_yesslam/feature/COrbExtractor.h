#pragma once
// ORB features spread evenly over the image, as ORB-SLAM does (its quadtree, here a per-level grid
// with round-robin selection of the strongest corner of each cell), with depth per keypoint from
// the registered depth image and the dynamic flag of eq. 3 from the dynamic-object mask.
#include <mrpt/config/CLoadableOptions.h>

#include <opencv2/features2d.hpp>
#include <vector>

#include "mrpt_yesslam/data/TFeatures.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** Detects and describes ORB features with an even spatial distribution. */
class COrbExtractor
{
   public:
	/** Section [ORB]. */
	struct TOptions : public TTableOptions<TOptions>
	{
		int numFeatures = 1000;
		int numLevels = 8;
		double scaleFactor = 1.2;
		/** FAST threshold. Low, as ORB-SLAM's retry threshold, so weak texture still yields corners
		 * in every cell; the strongest corners of each cell are kept first. */
		int fastThreshold = 7;
		int cellSize = 32;  //!< grid cell side in pixels of each pyramid level
		/** Keypoints inside the mask: false = detect and flag them dynamic (eq. 3; N_p counts them);
		 * true = do not detect there at all, so the feature budget goes to the static scene. */
		bool excludeMasked = false;

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	COrbExtractor() : COrbExtractor(TOptions()) {}
	/** Checks the options; throws InputError for invalid ones. */
	explicit COrbExtractor(const TOptions& opts);

	/** Extracts features of a BGR or grey image; `depthMetres` (CV_32F, may be empty) gives each
	 * keypoint's depth, `dynamicMask` (CV_8U, may be empty) the dynamic flags. */
	TFeatures extract(const cv::Mat& image, const cv::Mat& depthMetres = {}, const cv::Mat& dynamicMask = {}) const;

	/** Sets the dynamic flags from a mask (at the raw keypoint positions): extracting without a mask
	 * and flagging afterwards gives the same features as extract() with the mask, unless
	 * excludeMasked, so detection can run while features are extracted. */
	static void flagDynamic(TFeatures& features, const cv::Mat& dynamicMask);
	/** A keypoint's depth at raw pixel (x, y) of a depth image (CV_32F metres): the nearest pixel's,
	 * or 0 outside the image, without depth, or where its neighbourhood is not one surface. */
	static float depthAt(const cv::Mat& depthMetres, double x, double y);

	const TOptions& options() const { return opts_; }

   private:
	static constexpr int kHalfPatch = 15;  //!< half the 31-pixel ORB patch
	/** Candidate corners of every level, OpenCV ORB's way (keypoints in level-0 pixels, octave and
	 * size set, not yet oriented), outside `keepMask`'s zeros when it is given; `pyramid` gets the
	 * level images. */
	std::vector<cv::KeyPoint> detect(const cv::Mat& grey, const cv::Mat& keepMask, std::vector<cv::Mat>& pyramid) const;
	/** A keypoint's orientation (degrees) at `pt` of its pyramid level's image. */
	float orientation(const cv::Mat& level, cv::Point2f pt) const;
	/** ORB descriptors (one 32-byte row each) of oriented keypoints in level-0 pixels, read on
	 * their levels of `pyramid` (detect()'s). */
	cv::Mat describe(const std::vector<cv::Mat>& pyramid, const std::vector<cv::KeyPoint>& keypoints) const;

	TOptions opts_;
	cv::Ptr<cv::ORB> describer_;           //!< one-level ORB: describes one pyramid level's keypoints
	std::vector<int> perLevel_;            //!< feature quota of each level
	std::vector<int> candidatesPerLevel_;  //!< corners kept per level before the grid
	std::vector<int> discHalfWidth_;       //!< orientation disc: half-width of row |v|
};
}  // namespace mrpt_yesslam
