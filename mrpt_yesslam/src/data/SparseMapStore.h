#pragma once
// What CSparseMap holds behind its lock (storage), and the bookkeeping that keeps what is derived
// from the observations consistent on every change: the covisibility graph, the spanning tree,
// and the life of a point (recent, bad, forgotten). CSparseMap is the thread-safe face over it;
// the rules that use it live beside it, each in its own file (as stella_vslam splits its
// map_database from the modules that work on it):
//   MapCulling.h       which recent points and which redundant keyframes go (ORB-SLAM2's culling)
//   MapWindows.h       tracking's local keyframes and bundle-adjustment windows, and their write-back
//   MapCorrection.h    the essential graph and how a loop correction moves keyframes and points
//   MapSerialization.h the map file's map section, checked in full before it is used
// Private to the library: every function here expects the map's lock held by the caller.
#include <deque>
#include <map>
#include <memory>
#include <unordered_map>
#include <vector>

#include "mrpt_yesslam/data/CSparseMap.h"

namespace mrpt_yesslam
{
/** The sparse map's content and its bookkeeping (the caller holds the map's lock). */
struct TSparseMapStore
{
	std::map<TKeyFrameId, std::shared_ptr<CKeyFrame>> keyFrames;
	std::unordered_map<TPointId, CMapPoint> points;
	std::deque<TPointId> recent;  //!< points created in the last keyframes, oldest first
	/** Bad points to forget, oldest first, with the next keyframe id when they went bad. */
	std::deque<std::pair<TKeyFrameId, TPointId>> dead;
	std::vector<TKeyFrameId> dirty;  //!< keyframes whose ordered connections need sorting
	std::size_t numGoodKeyFrames = 0, numGoodPoints = 0;
	TKeyFrameId nextKeyFrame = 0;
	TPointId nextPoint = 0;
	std::uint64_t generation = 0;  //!< bumped by every map-wide correction
	/** Points the last group correction moved, with the keyframe that moved each; the next map-wide
	 * correction moves them with that keyframe (and forgets them). */
	std::map<TPointId, TKeyFrameId> correctedBy;

	/** See CSparseMap::addKeyFrame. */
	TKeyFrameId addKeyFrame(const TFrame& frame, double maxDepth, std::size_t* newPoints);
	/** Keypoint `kp` of `kf` observes `p`; the covisibility weights follow. */
	void addObservation(CMapPoint& p, CKeyFrame& kf, std::size_t kp);
	/** Keyframe `kf` no longer observes `p`; the covisibility weights follow. */
	void eraseObservation(CMapPoint& p, TKeyFrameId kf);
	/** Re-sorts the ordered connections of the keyframes whose weights changed. */
	void reorderDirty();
	/** Recounts every covisibility weight from the good points' observations (a loaded map's
	 * stored weights are only what its writer claimed). */
	void rebuildConnections();
	/** Sets the bad flag, counts it and schedules the point to be forgotten. */
	void markBad(CMapPoint& p);
	/** Marks `p` bad and removes all its observations (culling, erasing). */
	void dropPoint(CMapPoint& p);
	/** Removes the bad points erased long enough ago (kForgetBadPointsAfter keyframes). */
	void forgetDeadPoints();
	/** The good point `id` is, or was fused into; nullptr when bad or unknown. */
	const CMapPoint* goodPoint(TPointId id) const;
	/** T_w_c of keyframe `id`, of a bad one through its parent (throws for unknown ids). */
	mrpt::poses::CPose3D pose(TKeyFrameId id) const;
	/** See CSparseMap::covisible. */
	std::vector<TKeyFrameId> covisible(TKeyFrameId id, std::size_t max, int minWeight) const;
	/** See CSparseMap::goodAncestor. */
	TKeyFrameId goodAncestor(TKeyFrameId id) const;
	/** Adds point `p` to what tracking gets: id, position, descriptor and how it has been seen
	 * (TLocalMapPoints::normals, refDistances, refOctaves). */
	void appendPoint(TLocalMapPoints& out, const CMapPoint& p) const;
	/** See CSparseMap::pointsOfKeyFrames. */
	TLocalMapPoints pointsOfKeyFrames(const std::vector<TKeyFrameId>& ids) const;
	/** See CSparseMap::replacePoint (the caller re-sorts the dirty keyframes). */
	bool replacePoint(TPointId oldId, TPointId newId);
	/** See CSparseMap::fuse. */
	std::size_t fuse(const std::vector<TFuseCandidate>& candidates);
	/** ORB-SLAM2's KeyFrame::SetBadFlag (see CSparseMap::eraseKeyFrame); `kf` has a parent. */
	void eraseKeyFrame(CKeyFrame& kf);
	/** Removes the listed (point, keyframe) observations of a bundle result; a point left without
	 * observations goes bad. */
	void eraseOutliers(const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers);
};

}  // namespace mrpt_yesslam
