#pragma once
// What the system keeps of every processed frame after the frame itself is gone: where its pose
// hangs in the map (so the trajectory follows every later correction, as ORB-SLAM2 saves
// trajectories relative to reference keyframes), the pose it had online, and its frames.csv row.
// Thread-safe: the trajectory may be read while frames are processed.
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <vector>

#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/system/TSlamStats.h"
#include "mrpt_yesslam/tracking/CTracker.h"

namespace mrpt_yesslam
{
/** Every processed frame's record and row, in processing order. */
class CFrameRecords
{
   public:
	/** One frame's pose as the trajectory needs it. */
	struct TRecord
	{
		double t = 0;
		TAnchor anchor;               //!< where the pose hangs in the map (the trajectory follows corrections)
		mrpt::poses::CPose3D online;  //!< T_w_frame as reported when the frame was processed (filtered: [OnlinePose])
		/** T_w_frame as tracking solved it (what mapping's corrections are measured against). */
		mrpt::poses::CPose3D measured;
		bool tracked = false;
		bool hasPose = false;  //!< tracked, or lost after a tracked frame (coasted)
		/** The map's correction generation tracking saw (CSparseMap::generation): corrections are
		 * smoothed only among frames of one generation. */
		std::uint64_t generation = 0;
		/** The camera jerked at this frame (COnlinePoseFilter::jumped): smoothed() fits nothing across it. */
		bool jumped = false;
		/** The pose is its own keyframe's ([System] keyFrameFramePose = keyframe): never averaged. */
		bool pinned = false;
		/** Hangs the pose from `own`, the anchor on the keyframe made of this frame (pinned). */
		void pinTo(const TAnchor& own)
		{
			anchor = own;
			pinned = true;
		}
	};

	/** How smoothed() differs from trajectory() ([Output] lostInterpolate, correctionWindow,
	 * smoothingWindow): `lostInterpolate`, lost frames between tracked ones are placed between
	 * them; `correctionWindow` and `smoothingWindow`: see smoothed(). */
	explicit CFrameRecords(bool lostInterpolate, int correctionWindow = 0, int smoothingWindow = 0)
		: lostInterpolate_(lostInterpolate), correctionWindow_(correctionWindow), smoothingWindow_(smoothingWindow)
	{
	}

	/** Appends one frame. */
	void add(const TRecord& record, const TFrameLogRow& row);
	/** Marks the row of frame `frame` (searched from the newest) as the one a keyframe was made
	 * from; with `anchor`, its pose is then that keyframe's (pinned). */
	void markKeyFrame(std::size_t frame, const std::optional<TAnchor>& anchor);
	/** A pose for every frame that has one: the pose tracking measured relative to the keyframe it
	 * hangs from, carried by that keyframe's pose as `keyFramePoses` gives it (ORB-SLAM2's
	 * SaveTrajectoryTUM: the map's refinement reaches the frame, no later frame changes it; a
	 * frame whose keyframe the poses lack keeps its fallback; lost frames their coasted pose).
	 * `keyFramePoses` is read after the records, so that every keyframe a record hangs from is in
	 * it even while frames are being added. */
	TTrajectory trajectory(const std::function<std::map<TKeyFrameId, mrpt::poses::CPose3D>()>& keyFramePoses) const;
	/** trajectory(), then smoothed over later frames as well as earlier ones (after the run only).
	 * With a correctionWindow of W, each tracked frame's correction (its carried pose against its
	 * online one: what mapping moved its keyframe by since) is the mean of those of the W nearest
	 * tracked frames either side of it from the same correction generation and not across a
	 * relocalised frame, applied to its online pose (a pinned frame keeps its keyframe's pose; a
	 * frame whose keyframe the poses lack keeps its fallback and is in no neighbour's mean), and a
	 * coasted frame after an averaged one keeps its step from it. With a smoothingWindow of S, each
	 * such frame's position is then the value at its stamp of a parabola fitted in time through the
	 * positions of the nearest tracked frames, as many on each side and at most S, a side ending at
	 * another generation, a relocalised frame, a lost frame or S / 15 s (same lending and pinning
	 * rules; orientation its own; fewer than two on a side: left as solved). With lostInterpolate,
	 * lost frames between tracked ones are placed between them. */
	TTrajectory smoothed(const std::function<std::map<TKeyFrameId, mrpt::poses::CPose3D>()>& keyFramePoses) const;

   private:
	/** trajectory() with what smoothed() needs to know of each of its poses. */
	struct TCarried
	{
		TTrajectory poses;
		std::vector<bool> tracked, anchored, pinned;
		std::vector<mrpt::poses::CPose3D> online;  //!< each record's measured pose (not the filtered one)
		std::vector<std::uint64_t> stretch;
	};
	TCarried carried(const std::function<std::map<TKeyFrameId, mrpt::poses::CPose3D>()>& keyFramePoses) const;

   public:
	/** The poses the frames had when processed (see CYesSlamSystem::onlineTrajectory). */
	TTrajectory online() const;
	/** The rows, with where each pose comes from (EPoseSource). */
	std::vector<TFrameLogRow> frameLog() const;
	/** What a journal appends (CRunJournal): the frames recorded after the first `first`. */
	struct TSince
	{
		std::vector<TFrameLogRow> rows;  //!< `pose` as the run has it now: tracked, coasted or none
		TTrajectory online;              //!< the online poses of those of them that have one, in order
	};
	TSince since(std::size_t first) const;

   private:
	/** Where each record's pose comes from (Interpolated: lost, and filled in by smoothed()). */
	std::vector<EPoseSource> poseSources() const;

	/** A pose as its rotation matrix and translation (96 bytes; a CPose3D also caches its angles):
	 * read back into the same rotation and translation bit for bit. */
	struct TPoseRT
	{
		double v[12];
		static TPoseRT of(const mrpt::poses::CPose3D& p);
		mrpt::poses::CPose3D pose() const;
	};
	/** A TRecord as kept: a long run keeps one per frame (about 330 bytes instead of 770). */
	struct TStored
	{
		double t = 0;
		std::optional<TKeyFrameId> refKf;
		TPoseRT relative, online, measured;
		std::uint64_t generation = 0;
		bool tracked = false, hasPose = false, jumped = false, pinned = false;
		static TStored of(const TRecord& r);
		TRecord record() const;
	};

	bool lostInterpolate_;
	int correctionWindow_;
	int smoothingWindow_;
	mutable std::mutex mtx_;
	// Deques: a long run's records grow by blocks, never by a copy to twice their size (a vector's
	// growth held up to three times the records for a moment, and half of it unused after).
	std::deque<TStored> records_;    //!< guarded by mtx_
	std::deque<TFrameLogRow> rows_;  //!< guarded by mtx_
};
}  // namespace mrpt_yesslam
