#pragma once
// The sparse map shared by tracking and local mapping (and later loop closing), as ORB-SLAM2's Map
// and stella_vslam's map_database: keyframes and map points with stable ids, the observations that
// tie them, and what is derived from those and kept up to date on every change instead of being
// recomputed by scanning: the covisibility graph (weights, ordered lists), the spanning tree, and
// the list of recently created points that culling judges. All access goes through methods that
// take the map's one private lock and hand out copies, so no caller holds a lock for a whole frame
// and no caller keeps a stale copy of a keyframe's state.
//
// Every per-frame and per-keyframe operation is local: it touches one keyframe, its covisible
// keyframes and their points, never the whole map, so that cost does not grow with the map.
#include <mrpt/poses/CPose3D.h>

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <set>
#include <opencv2/core.hpp>
#include <shared_mutex>
#include <unordered_map>
#include <vector>

#include "mrpt_yesslam/data/CKeyFrame.h"
#include "mrpt_yesslam/data/CMapPoint.h"
#include "mrpt_yesslam/data/TFrame.h"
#include "mrpt_yesslam/data/TLocalMapPoints.h"

namespace mrpt_yesslam
{
/** One bundle-adjustment window, copied out of the map (see CLocalMapper). */
struct TBundleWindow
{
	std::uint64_t generation = 0;                       //!< the map's correction generation when copied
	std::vector<TKeyFrameId> keyFrames;                 //!< optimised
	std::vector<TKeyFrameId> fixedKeyFrames;            //!< observe the points, held fixed
	std::map<TKeyFrameId, mrpt::poses::CPose3D> poses;  //!< T_w_c of both kinds
	/** Measurements of both kinds (keypoints, depth), shared read-only, and their cameras. */
	std::map<TKeyFrameId, std::shared_ptr<const TFeatures>> features;
	std::map<TKeyFrameId, mrpt::img::TCamera> cameras;
	std::vector<TPointId> points;
	std::vector<mrpt::math::TPoint3D> positions;
	std::vector<std::map<TKeyFrameId, std::size_t>> observations;  //!< per point, restricted to the window
};

/** A map point found again in a keyframe (fusion): point `point` projects onto keypoint `keypoint` of `keyFrame`. */
struct TFuseCandidate
{
	TPointId point = -1;
	TKeyFrameId keyFrame = 0;
	std::size_t keypoint = 0;
};

/** Pose and time of one keyframe (trajectories, scenes). */
struct TKeyFramePose
{
	TKeyFrameId id = 0;
	double timestamp = 0;
	mrpt::poses::CPose3D pose;  //!< T_w_c (for a bad keyframe: through its parent)
	bool bad = false;
};

struct TSparseMapStore;

/** The map. Thread-safe. */
class CSparseMap
{
   public:
	CSparseMap();
	~CSparseMap();
	CSparseMap(const CSparseMap&) = delete;
	CSparseMap& operator=(const CSparseMap&) = delete;

	/** Adds a keyframe of a tracked frame: observations for the map points tracking matched
	 * (`frame->mapPoints`), and a new map point for every other static keypoint with depth up to
	 * `maxDepth` (RGB-D: depth gives the point at once, as in ORB-SLAM2's RGB-D mode). Updates the
	 * covisibility graph and hangs the keyframe in the spanning tree under its best-connected
	 * keyframe. Ids increase with every call. */
	TKeyFrameId addKeyFrame(const std::shared_ptr<const TFrame>& frame, double maxDepth,
							std::size_t* newPoints = nullptr);

	/** Stores the words of keyframe `id` (computed off the map's lock); false when unknown or bad. */
	bool setKeyFrameBow(TKeyFrameId id, std::shared_ptr<const TBow> bow);

	/** Number of keyframes that are not bad. */
	std::size_t numKeyFrames() const;
	/** Ids of the keyframes that are not bad, ascending. */
	std::vector<TKeyFrameId> keyFrameIds() const;
	/** Whether `id` names a keyframe (bad or not). */
	bool hasKeyFrame(TKeyFrameId id) const;
	/** Whether keyframe `id` was erased (throws std::out_of_range for unknown ids). */
	bool isBad(TKeyFrameId id) const;
	/** Keeps keyframe `id` from culling until as many unpinKeyFrame calls (a stage working on it,
	 * as the loop stage from detection to correction); false when it is unknown or already bad. */
	bool pinKeyFrame(TKeyFrameId id);
	/** Undoes one pinKeyFrame. */
	void unpinKeyFrame(TKeyFrameId id);
	/** One pinKeyFrame owned by a stage and undone when the owner goes, however its work on the
	 * keyframe ends (an exception, an early return); moved, it moves the pin. */
	class TPin
	{
	   public:
		TPin() = default;
		TPin(TPin&& o) noexcept : map_(o.map_), id_(o.id_) { o.map_ = nullptr; }
		TPin& operator=(TPin&& o) noexcept;
		TPin(const TPin&) = delete;
		TPin& operator=(const TPin&) = delete;
		~TPin();
		/** Whether it holds a pin (pinned() gives an empty one for an unknown or bad keyframe). */
		explicit operator bool() const { return map_ != nullptr; }
		/** The keyframe it pins (meaningful while it holds one). */
		TKeyFrameId id() const { return id_; }
		/** Hands the pin on without undoing it: whoever takes it over adopts it (adoptPin). */
		void release() noexcept { map_ = nullptr; }

	   private:
		friend class CSparseMap;
		TPin(CSparseMap* map, TKeyFrameId id) : map_(map), id_(id) {}
		CSparseMap* map_ = nullptr;
		TKeyFrameId id_ = 0;
	};
	/** Pins keyframe `id` (pinKeyFrame) and returns the pin; an empty one when it is unknown or
	 * already bad. */
	TPin pinned(TKeyFrameId id);
	/** Takes over a pin another stage made with pinKeyFrame and handed on with the keyframe. */
	TPin adoptPin(TKeyFrameId id) noexcept { return TPin(this, id); }
	/** addKeyFrame and a pin on the new keyframe in one step (one lock): a stage culling meanwhile
	 * cannot erase it before its owner holds it. */
	TPin addPinnedKeyFrame(const std::shared_ptr<const TFrame>& frame, double maxDepth);
	/** The nearest keyframe up the spanning tree from `id` (itself included) that is not bad. */
	TKeyFrameId goodAncestor(TKeyFrameId id) const;
	/** Number of map points that are not bad. */
	std::size_t numPoints() const;
	/** The current pose T_w_c of keyframe `id`, also of a bad one (through its parent); throws
	 * std::out_of_range for unknown ids. */
	mrpt::poses::CPose3D keyFramePose(TKeyFrameId id) const;
	/** A copy of keyframe `id` (throws std::out_of_range for unknown ids). */
	CKeyFrame keyFrame(TKeyFrameId id) const;
	/** A copy of map point `id` (throws std::out_of_range for ids never given). A point erased a few
	 * keyframes ago is forgotten: its copy then has only its id and the bad flag. */
	CMapPoint point(TPointId id) const;
	/** Points held in storage, good and recently erased (memory use; bounded by the map's size). */
	std::size_t numStoredPoints() const;
	/** Covisible keyframes of `id` from the stored graph, heaviest first: at most `max`, each
	 * sharing at least `minWeight` points. */
	std::vector<TKeyFrameId> covisible(TKeyFrameId id, std::size_t max, int minWeight = 1) const;
	/** ORB-SLAM2's local keyframes (Tracking::UpdateLocalKeyFrames): the good keyframes observing
	 * `seeds` (the frame's matched points), most shared first, then for each of those its
	 * `neighbours` best covisible keyframes, its children and its parent, at most `maxKeyFrames` in
	 * all. The first is the keyframe sharing most points: the frame's new reference. With no seed
	 * observed by a good keyframe, `fallback` (or its good ancestor) takes the seeds' place. */
	std::vector<TKeyFrameId> localKeyFrames(const std::vector<TPointId>& seeds, TKeyFrameId fallback,
											std::size_t maxKeyFrames, std::size_t neighbours = 10) const;
	/** The good points the keyframes `ids` observe, each once. */
	TLocalMapPoints pointsOfKeyFrames(const std::vector<TKeyFrameId>& ids) const;
	/** The same, with the pose of keyframe `posed` read under the same lock: a pose and points of
	 * one state of the map (the loop's verification measures against both). */
	TLocalMapPoints pointsOfKeyFrames(const std::vector<TKeyFrameId>& ids, TKeyFrameId posed,
									  mrpt::poses::CPose3D& pose) const;
	/** Points of one keyframe with their keypoint index (relocalisation). */
	TLocalMapPoints keyFramePoints(TKeyFrameId id, std::vector<std::size_t>* keypoints = nullptr) const;
	/** Number of good points keyframe `id` observes that at least `minObservations` keyframes see. */
	std::size_t numKeyFramePoints(TKeyFrameId id, std::size_t minObservations = 1) const;
	/** The good points among `ids` (in that order; bad or unknown ids are left out; a fused point
	 * is followed to the point that replaced it). */
	TLocalMapPoints pointsById(const std::vector<TPointId>& ids) const;
	/** Tracking statistics for culling: `visible` points were in view, `found` were matched (which
	 * clears their see-through count), `seenThrough` had farther surfaces measured where they should
	 * be in front; a point seen through in `seeThroughFrames` consecutive tracked frames has moved
	 * away (a person who stood still and left) and is erased (0 = never). Returns how many. */
	std::size_t countTracking(const std::vector<TPointId>& visible, const std::vector<TPointId>& found,
							  const std::vector<TPointId>& seenThrough = {}, int seeThroughFrames = 0);

	/** ORB-SLAM2's culling of recent points: found/visible below `minFoundRatio`, or fewer than
	 * `minObservations` keyframes two keyframes after creation. Only the points created in the last
	 * three keyframes are judged (the recent list); returns the number culled. */
	std::size_t cullRecentPoints(TKeyFrameId currentKf, double minFoundRatio, std::size_t minObservations);
	/** Size of the recent-points list (what the next culling will look at). */
	std::size_t numRecentPoints() const;
	/** ORB-SLAM2's KeyFrameCulling: each keyframe covisible with `currentKf` (never keyframe 0 or the
	 * current one) whose good points with depth up to `maxDepth` are at least `redundantRatio`
	 * observed by `minOtherObservers` other keyframes at the same or a finer scale (octave <= its
	 * own + 1) is erased. Returns the ids erased. */
	std::vector<TKeyFrameId> cullRedundantKeyFrames(TKeyFrameId currentKf, double redundantRatio = 0.9,
													std::size_t minOtherObservers = 3, double maxDepth = 1e9);
	/** Erases keyframe `id` (not keyframe 0): its observations go, its children are re-hung in the
	 * spanning tree, its measurements are dropped; its pose is kept relative to its parent. Returns
	 * false for keyframe 0, an unknown or an already bad keyframe. */
	bool eraseKeyFrame(TKeyFrameId id);
	/** Marks point `id` bad and removes its observations; false when unknown or already bad. */
	bool erasePoint(TPointId id);
	/** Fuses `oldId` into `newId`: every observation of the old point moves to the new one (unless
	 * that keyframe already observes the new one), tracking counts are added, the old point is bad
	 * and `replacedBy` names the new one. Returns false when either is unknown or bad. */
	bool replacePoint(TPointId oldId, TPointId newId);
	/** ORB-SLAM2's Fuse: for each candidate, a keypoint without a point gets an observation of the
	 * point; a keypoint holding another point has the two fused (the one with fewer observations
	 * goes). Returns the number of observations added plus points fused. */
	std::size_t fuse(const std::vector<TFuseCandidate>& candidates);

	/** The window around `id`: it and its `numCovisible` covisible keyframes are optimised, other
	 * keyframes that see the window's points are fixed (at most `maxFixed`), and so is keyframe 0. */
	TBundleWindow bundleWindow(TKeyFrameId id, std::size_t numCovisible, std::size_t maxFixed) const;
	/** Writes optimised poses and positions of window `w` back and removes the listed (point,
	 * keyframe) observations. Refused (returns false, nothing written) when a correction has been
	 * applied since the window was copied (its generation is older): the result would undo it.
	 * Keyframes and points erased meanwhile are skipped. */
	bool applyBundle(const TBundleWindow& w, const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses,
					 const std::vector<mrpt::math::TPoint3D>& positions,
					 const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers);
	/** The correction generation: bumped by every map-wide correction (loop closing, global BA). */
	std::uint64_t generation() const;

	/** Records a loop closed between keyframes `a` and `b` (both ways); false when either is unknown. */
	bool addLoopEdge(TKeyFrameId a, TKeyFrameId b);
	/** ORB-SLAM2's essential graph over the good keyframes: spanning-tree edges, covisibility edges
	 * of weight >= `minWeight`, and loop edges; each once, as (smaller id, larger id). */
	std::vector<std::pair<TKeyFrameId, TKeyFrameId>> essentialGraph(int minWeight) const;
	/** Moves the listed keyframes to the given poses, and every good point one of them observes
	 * rigidly with the first of them that observes it (ORB-SLAM2's correction of the loop's
	 * keyframe group before fusion). Starts a new correction generation. */
	void correctKeyFrames(const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses);
	/** A map-wide correction (pose graph): the listed keyframes get the given poses; every other
	 * good keyframe (one added while the correction was computed) moves rigidly with its nearest
	 * listed ancestor in the spanning tree; every good point moves with the keyframe that created it
	 * (or that keyframe's good ancestor), except a point the last correctKeyFrames moved: it moves
	 * with the keyframe that moved it then (ORB-SLAM2's mnCorrectedByKF), so that no point is
	 * corrected twice. Starts a new correction generation. */
	void applyCorrection(const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses);
	/** Every good keyframe (the first fixed) and every good point: ORB-SLAM2's global BA window. */
	TBundleWindow globalBundleWindow() const;
	/** Writes a global BA result back as applyBundle does, and moves the keyframes and points created
	 * since the window was copied with their ancestors (as applyCorrection). Refused (false) when a
	 * correction was applied meanwhile. Starts a new correction generation. */
	bool applyGlobalBundle(const TBundleWindow& w, const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses,
						   const std::vector<mrpt::math::TPoint3D>& positions,
						   const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers);

	/** Poses and times of all keyframes (bad ones resolved through their parents), by id. */
	std::vector<TKeyFramePose> keyFramePoses() const;
	/** Copies of all good points. */
	std::vector<CMapPoint> points() const;

	/** Format version written by serialize(); deserialize() refuses newer ones. */
	static constexpr std::uint32_t kSerialVersion = 1;
	/** Writes the whole map (map saving): every keyframe, bad ones too (their poses relative to their
	 * parents and the spanning tree's history), every good point, and the id counters, so that a
	 * loaded map goes on giving new ids after the old ones. */
	void serialize(std::ostream& out) const;
	/** Replaces the map's content with what serialize() wrote; throws std::runtime_error for a
	 * truncated stream, a newer version, or data whose ids do not resolve (an observation of an
	 * unknown keyframe, a keypoint index out of range), leaving the map as it was. */
	void deserialize(std::istream& in);

	/** Exchanges the whole content with `other` (a map read aside, checked in full, then put in
	 * place: loading a map file never leaves a half-replaced map). */
	void swapContent(CSparseMap& other);

   private:
	mutable std::shared_mutex mtx_;
	/** The content, behind mtx_ (src/data/SparseMapStore.h: storage and bookkeeping; the rules
	 * that work on it are in the files beside it). */
	std::unique_ptr<TSparseMapStore> s_;
};
}  // namespace mrpt_yesslam
