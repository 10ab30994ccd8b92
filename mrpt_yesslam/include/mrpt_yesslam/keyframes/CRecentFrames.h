#pragma once
// The frames Algorithm 1 may still choose a keyframe from: the last frameBuffer tracked frames,
// each with where its pose hangs in the map (its reference keyframe and the relative pose as
// tracking read them). The interval's choice is known only when the interval closes, frames
// later; a frame taken from here is placed where the map is then (a loop correction or global BA
// since it was tracked moved its keyframe and the points it matched).
#include <deque>
#include <memory>

#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/data/TFrame.h"
#include "mrpt_yesslam/data/TAnchor.h"

namespace mrpt_yesslam
{
/** The recent frames of a run, for delayed (semantic) keyframe decisions. */
class CRecentFrames
{
   public:
	/** Keeps at most `capacity` frames (at least one). */
	explicit CRecentFrames(std::size_t capacity) : capacity_(std::max<std::size_t>(1, capacity)) {}
	/** Adds the newest frame and its anchor; the oldest goes when the buffer is full. */
	void push(std::shared_ptr<const TFrame> frame, const TAnchor& anchor);
	/** Frame `frameId` if it is still here and was tracked, at its pose in `map` as it is now (a
	 * copy when that moved it); null otherwise. */
	std::shared_ptr<const TFrame> tracked(std::size_t frameId, const CSparseMap& map) const;
	/** Lets go of every frame (their images are what the buffer costs). */
	void clear() { frames_.clear(); }

   private:
	struct TEntry
	{
		std::shared_ptr<const TFrame> frame;
		TAnchor anchor;
	};
	std::size_t capacity_;
	std::deque<TEntry> frames_;
};

/** Eq. 12-16 between a frame and a keyframe: the motion amplitude D of the rigid motion the 3D
 * points they share give (each measured by its own depth), or of their relative pose when fewer
 * than 10 are shared. */
double motionToKeyFrame(const TFrame& f, const CKeyFrame& kf);
}  // namespace mrpt_yesslam
