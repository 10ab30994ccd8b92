#pragma once
// The sparse map shared by tracking and local mapping: keyframes, map points and the observations
// that tie them (the covisibility graph is derived from those). All access goes through methods
// that take the map's one private lock, and hand out copies (snapshots), so that no caller ever
// holds a lock for a whole frame.
#include <mrpt/math/TPoint3D.h>
#include <mrpt/poses/CPose3D.h>

#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <shared_mutex>
#include <vector>

#include "mrpt_yesslam/data/TFrame.h"

namespace mrpt_yesslam
{
/** A 3D landmark. */
struct CMapPoint
{
	TPointId id = -1;
	mrpt::math::TPoint3D position;	//!< world frame, metres
	cv::Mat descriptor;	 //!< 1x32 CV_8U, from the keyframe that created it
	cv::Vec3b color;  //!< BGR
	std::map<std::size_t, std::size_t> observations;  //!< keyframe id -> keypoint index
	std::size_t firstKeyFrame = 0;
	int visible = 1;  //!< times it was inside a tracked frame's view
	int found = 1;	//!< times tracking matched it
	bool bad = false;
};

/** A keyframe: a tracked frame kept for the map. */
struct CKeyFrame
{
	std::size_t id = 0;
	std::shared_ptr<const TFrame> frame;
	mrpt::poses::CPose3D pose;	//!< T_w_c; written only by the optimisers
	std::vector<TPointId> mapPoints;  //!< per keypoint, -1 = none
};

/** What tracking searches a frame against: points near the current view, copied out. */
struct TLocalMapPoints
{
	std::vector<TPointId> ids;
	std::vector<mrpt::math::TPoint3D> positions;
	cv::Mat descriptors;  //!< one row per point
};

/** One bundle-adjustment window, copied out of the map (see CLocalBundleAdjuster). */
struct TBundleWindow
{
	std::vector<std::size_t> keyFrames;	 //!< optimised
	std::vector<std::size_t> fixedKeyFrames;  //!< observe the points, held fixed
	std::map<std::size_t, mrpt::poses::CPose3D> poses;	//!< T_w_c of both kinds
	std::map<std::size_t, std::shared_ptr<const TFrame>> frames;
	std::vector<TPointId> points;
	std::vector<mrpt::math::TPoint3D> positions;
	std::vector<std::map<std::size_t, std::size_t>> observations;  //!< per point, restricted to the window
};

/** The map. Thread-safe. */
class CSparseMap
{
   public:
	/** Adds a keyframe of a tracked frame: observations for the map points tracking matched
	 * (`frame->mapPoints`), and a new map point for every other static keypoint with depth up to
	 * `maxDepth` (RGB-D: depth gives the point at once, as in ORB-SLAM2's RGB-D mode). */
	std::size_t addKeyFrame(const std::shared_ptr<const TFrame>& frame, double maxDepth, std::size_t* newPoints = nullptr);

	std::size_t numKeyFrames() const;
	/** Number of map points that are not bad. */
	std::size_t numPoints() const;
	/** The current pose T_w_c of keyframe `id` (throws std::out_of_range for unknown ids). */
	mrpt::poses::CPose3D keyFramePose(std::size_t id) const;
	/** A copy of keyframe `id` (throws std::out_of_range for unknown ids). */
	CKeyFrame keyFrame(std::size_t id) const;
	/** Keyframe ids sorted by the number of map points they share with `id`, most first (at most `max`). */
	std::vector<std::size_t> covisible(std::size_t id, std::size_t max) const;
	/** Points seen by keyframe `id` and its `numCovisible` best covisible keyframes. */
	TLocalMapPoints localPoints(std::size_t id, std::size_t numCovisible) const;
	/** Points of one keyframe with their keypoint index (relocalisation). */
	TLocalMapPoints keyFramePoints(std::size_t id, std::vector<std::size_t>* keypoints = nullptr) const;
	/** The good points among `ids` (in that order; bad or unknown ids are left out). */
	TLocalMapPoints pointsById(const std::vector<TPointId>& ids) const;
	/** Tracking statistics for culling: `visible` points were in view, `found` were matched. */
	void countTracking(const std::vector<TPointId>& visible, const std::vector<TPointId>& found);
	/** ORB-SLAM2's culling of recent points: found/visible below `minFoundRatio`, or fewer than
	 * `minObservations` keyframes after two more keyframes. Returns the number culled. */
	std::size_t cullRecentPoints(std::size_t currentKf, double minFoundRatio, std::size_t minObservations);

	/** The window around `id`: it and its `numCovisible` covisible keyframes are optimised, other
	 * keyframes that see the window's points are fixed (at most `maxFixed`), and so is keyframe 0. */
	TBundleWindow bundleWindow(std::size_t id, std::size_t numCovisible, std::size_t maxFixed) const;
	/** Writes optimised poses and positions back; removes the listed (point, keyframe) observations. */
	void applyBundle(
		const std::map<std::size_t, mrpt::poses::CPose3D>& poses, const std::vector<TPointId>& points,
		const std::vector<mrpt::math::TPoint3D>& positions, const std::vector<std::pair<TPointId, std::size_t>>& outliers);

	/** Poses of all keyframes, by id. */
	std::vector<mrpt::poses::CPose3D> keyFramePoses() const;
	/** Timestamps of all keyframes, by id. */
	std::vector<double> keyFrameTimes() const;
	/** Copies of all good points. */
	std::vector<CMapPoint> points() const;

   private:
	void eraseObservation(CMapPoint& p, std::size_t kf);

	mutable std::shared_mutex mtx_;
	std::vector<CKeyFrame> keyFrames_;
	std::map<TPointId, CMapPoint> points_;
	TPointId nextPoint_ = 0;
};
}  // namespace mrpt_yesslam
