#pragma once
// Matching ORB descriptors by Hamming distance (paper eq. 6).
//
// Tracking uses projection-guided search, as ORB-SLAM2 and stella_vslam do: each map point is
// projected with the predicted pose and compared only with the keypoints within a few pixels.
// That is both faster (tens of candidates instead of a thousand) and more reliable than global
// matching: in an office, repeated texture (keyboards, books) gives many look-alike descriptors
// that a global matcher (brute force, or the paper's FLANN-LSH, which is an approximation of brute
// force) pairs wrongly, while geometry rules them out here. Without a pose prediction
// (initialisation, relocalisation) we use exact brute force with Lowe's ratio test: with a few
// hundred descriptors per side it takes about a millisecond, so LSH's approximation buys nothing.
#include <limits>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "mrpt_yesslam/data/TFrame.h"
#include "mrpt_yesslam/data/TLocalMapPoints.h"

namespace mrpt_yesslam
{
/** Hamming distance between two 32-byte ORB descriptors. */
int orbDistance(const unsigned char* a, const unsigned char* b);

/** The two smallest distances seen and the index of the smallest: Lowe's ratio test, shared by
 * every descriptor search (tracking, relocalisation, loop verification). */
struct TBestTwo
{
	int best = std::numeric_limits<int>::max(), second = std::numeric_limits<int>::max(), index = -1;
	/** Counts one candidate at distance `dist`. */
	void add(int dist, int idx)
	{
		if (dist < best)
		{
			second = best;
			best = dist;
			index = idx;
		}
		else if (dist < second)
			second = dist;
	}
	/** A match within `maxDist` and clearly better than the runner-up (if any). */
	bool accepted(int maxDist, double ratio) const
	{
		return index >= 0 && best <= maxDist && (second == std::numeric_limits<int>::max() || best <= ratio * second);
	}
	/** The same with the runner-up strictly farther: a tie, two equally near twins included, is
	 * refused (ORB-SLAM2's SearchByBoW; loop verification, where a wrong pair costs a false loop). */
	bool acceptedStrictly(int maxDist, double ratio) const
	{
		return index >= 0 && best <= maxDist && (second == std::numeric_limits<int>::max() || best < ratio * second);
	}
};

/** A keypoint-to-point match. */
struct TMatch
{
	std::size_t keypoint = 0;  //!< index in the frame
	std::size_t point = 0;     //!< index in the point set
	int distance = 0;          //!< Hamming
};

/** Descriptor matching. Stateless apart from its thresholds. */
class COrbMatcher
{
   public:
	/** `maxDistance`: largest accepted Hamming distance (ORB-SLAM2's TH_HIGH is 100, TH_LOW 50);
	 * `ratio`: best must be below ratio x second best (Lowe's test). */
	explicit COrbMatcher(int maxDistance = 100, double ratio = 0.8) : maxDist_(maxDistance), ratio_(ratio) {}

	/** Projects `points` with the camera pose `Twc` into `frame` and matches each to the best static
	 * keypoint within `radius` pixels (times the keypoint's scale). Keypoints already matched
	 * (frame.mapPoints[i] >= 0, when `skipMatched`) are left out. Indices of points that fell inside
	 * the image go to `inView`. Each keypoint is matched at most once (the closest descriptor wins).
	 * With `viewChecks` and points that carry how they have been seen (TLocalMapPoints::hasViews),
	 * as ORB-SLAM2's local-map search: a point farther or nearer than its pyramid can see it, or
	 * seen more than 60 degrees off its mean viewing direction, is not in view; the others are
	 * searched at the pyramid level their distance predicts (radius times that level's scale,
	 * keypoints of that level or the one below). */
	std::vector<TMatch> searchByProjection(const TFrame& frame, const mrpt::poses::CPose3D& Twc,
										   const TLocalMapPoints& points, double radius,
										   std::vector<std::size_t>* inView = nullptr, bool skipMatched = false,
										   double scaleFactor = 1.2, bool viewChecks = false) const;

	/** Brute force: the best point for each static keypoint of `frame`, with the ratio test and
	 * one match per point. */
	std::vector<TMatch> matchBruteForce(const TFrame& frame, const cv::Mat& pointDescriptors) const;

   private:
	int maxDist_;
	double ratio_;
};
}  // namespace mrpt_yesslam
