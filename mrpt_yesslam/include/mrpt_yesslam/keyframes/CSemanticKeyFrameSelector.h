#pragma once
// The paper's keyframe selection (section 2.3, Algorithm 1, eq. 8-17): frames are grouped into
// intervals of N_I = 5 (3 after three consecutive frames of excessive motion); in each interval the
// frame least similar to the reference keyframe (global similarity S_G, eq. 10, of semantic region
// vectors and box areas) is the candidate; it becomes the next reference and, with more than 20
// tracking inliers, a keyframe. Frames with too few static features (N_sp <= 0.5 N_p) are skipped.
//
// Where the paper is vague we chose (and docs/ says so):
// - eta (eq. 8) as written is at most 0.5 (identical boxes give A_u / 2A); by default we use
//   2 A_u / (A_cur + A_ref) (the Dice coefficient) so that S_G spans [0,1] like J; `etaAsWritten`
//   restores the formula. Boxes are paired by class, greedily by overlap.
// - Two empty region vectors, or two frames without boxes, are identical (similarity 1).
// - An object is present in every region its box overlaps.
// - Only D >= D_max counts as excessive motion (the text: "greater motion amplitude"); the short
//   interval ends at the first frame inside (D_min, D_max). Frames with D <= D_min are not
//   candidates: a still camera would otherwise add near-identical keyframes, the redundancy the
//   method exists to avoid. Gamma, D_min and D_max are not given in the paper; ours are options.
#include <mrpt/config/CLoadableOptions.h>

#include <Eigen/Core>
#include <optional>
#include <set>
#include <vector>

#include "mrpt_yesslam/types.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** Eq. 9's semantic vectors: for each of cols x rows image regions, the classes present in it. */
std::vector<std::set<int>> semanticRegionVectors(const std::vector<TDetection>& dets, cv::Size image, int cols,
												 int rows);

/** Eq. 9/11: mean over regions of |A_i ∩ B_i| / |A_i ∪ B_i| (1 for two empty regions). */
double jaccardSimilarity(const std::vector<std::set<int>>& a, const std::vector<std::set<int>>& b);

/** Eq. 8: box-area similarity. asWritten: A_u / (A_cur + A_ref); else 2 A_u / (A_cur + A_ref). */
double areaSimilarity(const std::vector<TDetection>& cur, const std::vector<TDetection>& ref, bool asWritten = false);

/** Eq. 10: S_G = gamma J + (1 - gamma) eta. */
inline double globalSimilarity(double J, double eta, double gamma)
{
	return gamma * J + (1.0 - gamma) * eta;
}

/** Eq. 16: D = |t| + min(2 pi - |R|, |R|), |R| the rotation angle (metres + radians). */
double motionAmplitude(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

/** Eq. 12-15: R, t with cur ~ R ref + t from matched 3D points (SVD on centred sets, reflection
 * fixed). Needs at least 3 points; returns false when degenerate. */
bool rigidMotionFromPoints(const std::vector<Eigen::Vector3d>& cur, const std::vector<Eigen::Vector3d>& ref,
						   Eigen::Matrix3d& R, Eigen::Vector3d& t);

/** What the selector needs to know about one tracked frame. */
struct TKeyFrameInput
{
	std::size_t frameId = 0;
	std::vector<TDetection> detections;
	cv::Size imageSize;
	std::size_t numFeatures = 0;  //!< N_p
	std::size_t numStatic = 0;    //!< N_sp
	std::size_t numInliers = 0;   //!< N_in: tracking inliers
	double motion = 0;            //!< D (eq. 16) relative to the reference keyframe
};

/** Algorithm 1 as a state machine fed one frame at a time. */
class CSemanticKeyFrameSelector
{
   public:
	/** Section [KeyFrames]. */
	struct TOptions : public TTableOptions<TOptions>
	{
		int gridCols = 2, gridRows = 2;  //!< n = cols x rows regions (the paper's example: 4)
		double gamma = 0.5;              //!< eq. 10 weight of J
		int interval = 5;                //!< N_I
		int shortInterval = 3;           //!< N_I after `excessiveFrames` consecutive frames with D >= maxMotion
		int excessiveFrames = 3;
		double minMotion = 0.01;      //!< D_min (m + rad)
		double maxMotion = 0.30;      //!< D_max (m + rad)
		double minStaticRatio = 0.5;  //!< skip frames with N_sp <= this * N_p
		std::size_t minInliers = 20;  //!< a candidate needs N_in > this
		bool etaAsWritten = false;    //!< eq. 8 literally (max 0.5) instead of the Dice form

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	/** A decision: the frame that became a keyframe (possibly an earlier frame of the interval). */
	struct TDecision
	{
		std::size_t frameId = 0;
		double similarity = 1;  //!< its S_G to the previous reference
	};

	CSemanticKeyFrameSelector() : CSemanticKeyFrameSelector(TOptions()) {}
	explicit CSemanticKeyFrameSelector(const TOptions& opts);

	/** Feeds one frame; returns the keyframe chosen when an interval closes (or the first keyframe). */
	std::optional<TDecision> addFrame(const TKeyFrameInput& f);

	/** Makes `f` the reference keyframe (inserted by another rule) and starts a new interval after it. */
	void restart(const TKeyFrameInput& f);
	/** S_G of a frame to the current reference keyframe. */
	double similarityToReference(const TKeyFrameInput& f) const;
	/** The current interval length N_I. */
	int currentInterval() const { return shortMode_ ? opts_.shortInterval : opts_.interval; }
	/** Id of the reference keyframe (nullopt before the first). */
	std::optional<std::size_t> referenceId() const;
	const TOptions& options() const { return opts_; }

   private:
	TOptions opts_;
	std::optional<TKeyFrameInput> ref_;
	std::optional<TKeyFrameInput> cand_;
	double candSim_ = 2;
	int inInterval_ = 0, intervalLen_ = 5, excessive_ = 0;
	bool shortMode_ = false;
};
}  // namespace mrpt_yesslam
