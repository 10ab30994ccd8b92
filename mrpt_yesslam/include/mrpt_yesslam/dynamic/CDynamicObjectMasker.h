#pragma once
// Cuts dynamic objects out of the image (paper section 2.1, eq. 2-5): inside each box of a dynamic
// class, a 4-neighbour flood fill on the depth image separates the object from the background
// behind it, so that only the object's features are dropped (eq. 3), not the whole box.
//
// Where the paper is vague we chose, as documented in docs/:
// - We fill depth in metres, not an 8-bit image: tolerances are metres. The paper's d_lo = d_up = 5
//   on an 8-bit depth image spanning ~0..6.5 m is about 0.13 m.
// - "Edge enhancement" (eq. 4) is Laplacian sharpening, f - k * lap(f), which steepens every depth
//   discontinuity, followed by the Gaussian blur of eq. 5 against sensor noise.
// - The fill compares each pixel with its filled neighbour (floating range) rather than with the
//   seed only, so a person leaning towards the camera is filled whole; the sharpened edges stop it.
// - Seed: among the valid pixels of the box's central part, the nearest to the box centre whose
//   depth lies in the central part's dominant (foreground) depth mode.
// - Missing depth (0) never joins a fill; holes enclosed by the filled object are added afterwards,
//   and the mask is dilated a little, because features on silhouettes are unreliable (as DynaSLAM).
// - When the fill fails (no valid depth, leaks into nearly the whole box, or finds almost nothing)
//   the whole box is used, configurably.
// - Beyond the paper: the fill stays within maxDepthRange of the seed depth, so it cannot run along
//   the floor under a person's feet (or a desk under a monitor) to the edges of the box.
// - Beyond the paper: detectors flicker (a person missed for one frame). A frame whose features on a person are all
//   used can become a keyframe and put the person into the map, which then drags the camera along with the person for
//   many frames (as one missed detection did on the walking_static sim). So a dynamic object seen in the last frames
//   but missed now is still masked from its last box, grown, for up to holdFrames frames, as detection-based dynamic
//   SLAM systems with missed-detection compensation do (e.g. Detect-SLAM's propagation).
#include <mrpt/config/CLoadableOptions.h>

#include <opencv2/core.hpp>
#include <vector>

#include "mrpt_yesslam/types.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** What happened inside one dynamic box. */
struct TMaskRegion
{
	int detection = -1;      //!< index into the detections given
	std::size_t pixels = 0;  //!< pixels marked dynamic for it
	bool usedBox = false;    //!< fell back to (or was configured to use) the whole box
	bool held = false;       //!< not detected in this frame: held from an earlier one (detection = -1)
	cv::Point seed{-1, -1};  //!< fill seed, (-1,-1) without a fill
};

/** Masks of one frame. */
struct TDynamicMask
{
	cv::Mat mask;            //!< CV_8UC1, 255 = dynamic
	cv::Mat classLabels;     //!< CV_16UC1, classId + 1 of the dynamic object at each masked pixel, 0 = none
	cv::Mat instanceLabels;  //!< CV_16UC1, detection index + 1 at each masked pixel, 0 = none
	std::vector<TMaskRegion> regions;
};

/** The masker (one per camera; not thread-safe, it keeps scratch images). */
class CDynamicObjectMasker
{
   public:
	/** Section [DynamicMask] of the config. */
	struct TOptions : public TTableOptions<TOptions>
	{
		/** edge_fill (the paper's method) | fill (plain depth flood fill) | box (whole box) */
		std::string method = "edge_fill";
		/** Fill tolerance towards the camera between neighbours, metres. The paper's 5 grey levels
		 * (about 0.13 m): on yesslam-sim, of the keypoints on people inside their boxes, plain fill
		 * finds 91 % and edge_fill 79 %, against 72 % and 70 % with 0.06 m, for 2 % fewer static
		 * keypoints kept (bench/bench_masking.sh). */
		double loDiff = 0.13;
		double upDiff = 0.13;  //!< fill tolerance away from the camera between neighbours, metres
		/** What a pixel's depth is compared with: "neighbour" (a floating range: the filled
		 * neighbour, so the fill follows a person's body as it bends away, with maxDepthRange as the
		 * cap) or "seed" (eq. 2 as written: the seed's value, a fixed range). */
		std::string fillCompare = "neighbour";
		double laplacianGain = 1.0;  //!< k in f - k * lap(f)
		int laplacianKernel = 3;     //!< aperture of the Laplacian (1, 3, 5, 7)
		double blurSigma = 1.0;      //!< sigma of the Gaussian blur (eq. 5), pixels (at the fill resolution)
		double boxMargin = 0.05;     //!< the fill may leave the box by this share of its size
		double maxFillRatio = 0.97;  //!< a fill covering more of the box than this leaked: use the box
		double minFillRatio = 0.05;  //!< a fill covering less of the box than this failed: use the box
		bool fallbackToBox = true;   //!< on failure use the whole box (false: mask nothing)
		int dilatePixels = 3;        //!< grow each object's mask by about this many (full-resolution) pixels
		double maxDepth = 8.0;       //!< depth beyond this is treated as missing, metres
		/** The fill never includes depth farther than this from the seed's (metres; 0 = no limit).
		 * Not in the paper: it stops fills that run along the floor or a desk the object touches. */
		double maxDepthRange = 0.5;
		/** Fill at 1/downsample of the image side (1 = full resolution). Blur and Laplacian sizes are
		 * in pixels of that resolution. */
		int downsample = 2;
		/** A dynamic object missed by the detector is still masked for up to this many frames after
		 * its last detection (0 = off). Assumes consecutive frames of one camera. */
		int holdFrames = 5;
		/** Each frame a held box grows by this share of its size on every side. */
		double holdGrow = 0.05;

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	CDynamicObjectMasker() : CDynamicObjectMasker(TOptions()) {}
	/** Checks the options; throws InputError for invalid ones. */
	explicit CDynamicObjectMasker(const TOptions& opts);

	/** Masks the dynamic detections of one frame; `depthMetres` is CV_32FC1 (0 = no depth), the
	 * image size. Non-dynamic detections are ignored. Frames must come in order (see holdFrames). */
	TDynamicMask compute(const cv::Mat& depthMetres, const std::vector<TDetection>& detections);

	/** The same fill for every detection given, of any class, without held objects: per-pixel
	 * class and instance labels (later detections drawn over earlier ones) for the dense semantic
	 * map. Const and without state: safe beside compute() on another thread. */
	TDynamicMask segmentAll(const cv::Mat& depthMetres, const std::vector<TDetection>& detections) const;

	/** Eq. 3: true for keypoints inside the mask (dynamic, to be dropped). */
	static std::vector<bool> classifyKeypoints(const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& mask);

	const TOptions& options() const { return opts_; }
	/** Forgets held detections (call between unrelated sequences or images). */
	void reset() { held_.clear(); }

   private:
	/** A dynamic detection of an earlier frame, `age` frames ago. */
	struct THeld
	{
		TDetection det;
		int age = 0;
	};
	/** The detections to mask this frame: those given, then held ones (flagged in `held`). */
	std::vector<TDetection> withHeld(const std::vector<TDetection>& dets, std::vector<bool>& held);

	/** Fills the boxes of `dets` (only the dynamic ones with `onlyDynamic`); `held` flags each. */
	TDynamicMask segment(const cv::Mat& depth, const std::vector<TDetection>& dets, const std::vector<bool>& held,
						 bool onlyDynamic) const;
	/** The image the fill runs on (enhanced or plain depth, float metres, 0 = missing). */
	cv::Mat prepare(const cv::Mat& depth) const;
	/** Fills one box of `raw` (depth in metres, 0 = missing): `out` is the object's mask over the
	 * frame rectangle `outRoi`. Returns false when the fill failed. */
	bool fillBox(const cv::Mat& raw, const cv::Rect& box, cv::Mat& out, cv::Rect& outRoi, cv::Point& seed) const;

	TOptions opts_;
	std::vector<THeld> held_;
};
}  // namespace mrpt_yesslam
