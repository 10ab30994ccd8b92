// CTracker's motion model: the last frames it keeps, the velocity they give, the frame interval.
#include "mrpt_yesslam/tracking/CTracker.h"

#include <mrpt/poses/Lie/SE.h>
#include <mrpt/poses/Lie/SO.h>

#include <algorithm>
#include <limits>
#include <numeric>

#include "mrpt_yesslam/geometry/RelativeMotion.h"

namespace mrpt_yesslam
{
void CTracker::setLastFrame(const std::shared_ptr<const TFrame>& f)
{
	// The frame track() saw: both poses of the velocity are from the map as tracking read it (a
	// correction landing since, on the mapping stage, is in neither); its anchor carries it over.
	const bool fromTrack = tracked_ && tracked_->frameId == f->id;
	const bool relocalised = relocalisedFrame_ && *relocalisedFrame_ == f->id;
	if (last_ && last_->tracked && f->tracked && relocalised)
	{
		// The step onto a relocalised frame is a jump from where tracking had drifted (or the camera was carried), not
		// the camera's motion: the velocity from before it stays, for the prediction and the rolling shutter, and is
		// not averaged with the jump (averaged, it lost the next frame). The prior waits lostVelocityFrames steps.
		smoothMotions_ = 0;
		if (f->timestamp < last_->timestamp)  // and a clock that went back: the motions before are of another
		{
			recentMotion_.clear();
			velocity_.reset();
		}
	}
	else if (last_ && last_->tracked && f->tracked)
	{
		velocity_ = f->pose - (fromTrack ? tracked_->base : last_->pose);  // T_{k-1,k} = T_w_{k-1}^-1 T_w_k
		velocityInterval_ = f->timestamp - last_->timestamp;
		lostRun_ = 0;
		if (velocityInterval_ < 0)  // time went back: the motions before are of another clock
		{
			recentMotion_.clear();
			smoothMotions_ = 0;
		}
		recentMotion_.push_back({mrpt::poses::Lie::SE<3>::log(*velocity_), velocityInterval_});
		smoothMotions_++;
		while (recentMotion_.size() > opts_.lostVelocityFrames) recentMotion_.pop_front();
	}
	else if (!f->tracked)
	{
		// Lost (a person fills the view, or matching failed): the camera does not stop, so the next
		// guess continues the last velocity measured on tracked frames, damped each frame, for a
		// while (ORB-SLAM2 keeps predicting with its motion model too); then the pose is held.
		// Guessed poses never feed the velocity.
		if (velocity_ && ++lostRun_ <= opts_.lostCoastFrames && opts_.lostDamping > 0)
		{
			const auto v =
				lostRun_ == 1 && !recentMotion_.empty() ? meanRecentMotion() : mrpt::poses::Lie::SE<3>::log(*velocity_);
			velocity_ = scaledTwist(v, opts_.lostDamping);
		}
		else
			velocity_.reset();
		// The motions before the loss are spent on this coast: after it, the velocity (and the
		// rolling-shutter correction with it) is measured anew, never averaged with them.
		recentMotion_.clear();
		smoothMotions_ = 0;
	}
	// Every frame ages the mover regions, also one the local map did not confirm (lost, or kept by
	// step 3): a region is where the mover was a few frames ago, and a loss does not keep the
	// mover there (after six lost frames a region from before still made keypoints uncertain).
	if (moversFrame_ != f->id) ageMovers();
	frameInterval_ = measuredFrameInterval();  // the motions and their times change only here
	last_ = f;
	if (fromTrack && map_.generation() != tracked_->generation)
	{
		// A map-wide correction (loop, global BA) landed since tracking: the frame's pose is in the
		// map from before it, so it hangs from its keyframe as tracking read it (ORB-SLAM2's
		// UpdateLastFrame with the relative pose recorded when tracked).
		lastAnchor_ = tracked_->anchor;
	}
	else
	{
		// Only local BA since (millimetres): the last frame keeps the pose tracking gave it, as the prediction's start.
		// Following the keyframe through local BA instead, or hanging a frame that became a keyframe from it, changed
		// nothing on the simulator and made the real Bonn slice worse.
		lastAnchor_.refKf = referenceKeyFrame();
		if (lastAnchor_.refKf) lastAnchor_.relative = f->pose - map_.keyFramePose(*lastAnchor_.refKf);
	}
}

std::optional<mrpt::poses::CPose3D> CTracker::motionOver(double seconds) const
{
	// A lost frame's velocity is a guess (coasting): it moves nothing.
	if (!velocity_ || lostRun_ > 0 || !(velocityInterval_ > 0)) return std::nullopt;
	// The mean motion of the last tracked frames (as a lost frame coasts), not the last one alone: each frame's pose
	// carries its own noise, which a velocity scaled up by readout / interval passes on; the mean helped the correction
	// on the real Bonn slice and the rolling-shutter sims, though not on a very short run.
	// The mean is the motion over the time the frames span (their sum over their summed intervals):
	// live input drops frames, and a step over two intervals is not twice the speed.
	if (recentMotion_.empty())
		return scaledTwist(mrpt::poses::Lie::SE<3>::log(*velocity_), seconds / velocityInterval_);
	mrpt::math::CVectorFixedDouble<6> sum;
	sum.setZero();
	double span = 0;
	for (const auto& m : recentMotion_)
		if (m.seconds > 0)  // a motion without time (equal stamps) says nothing of the speed
		{
			for (int k = 0; k < 6; k++) sum[k] += m.twist[k];
			span += m.seconds;
		}
	if (!(span > 0)) return std::nullopt;
	return scaledTwist(sum, seconds / span);
}

mrpt::math::CVectorFixedDouble<6> CTracker::meanRecentMotion() const
{
	// The mean motion of the last tracked frames, not the last one alone: the frames just before a person blinds the
	// camera are the ones the person already pulls on (a still camera coasting on that last step drifted off in the
	// sims), while a smooth camera path keeps its velocity in a short mean.
	// Per frame interval: a step over a dropped frame (two intervals) counts as two of them.
	mrpt::math::CVectorFixedDouble<6> v;
	v.setZero();
	for (const auto& m : recentMotion_)
	{
		const double intervals = intervalsIn(m.seconds, frameInterval_);
		for (int k = 0; k < 6; k++) v[k] += m.twist[k] / intervals / static_cast<double>(recentMotion_.size());
	}
	return v;
}

double CTracker::measuredFrameInterval() const
{
	// The median, not the mean: a step over a dropped frame is one of the few, and a mean would
	// take it for a slower sensor. The lower median: of two steps (just after a loss), one over a
	// dropped frame, the shorter is the sensor's (drops only lengthen intervals).
	std::vector<double> s;
	for (const auto& m : recentMotion_)
		if (m.seconds > 0) s.push_back(m.seconds);
	if (s.empty()) return velocityInterval_ > 0 ? velocityInterval_ : 0.0;
	const auto mid = s.begin() + static_cast<std::ptrdiff_t>((s.size() - 1) / 2);
	std::nth_element(s.begin(), mid, s.end());
	return *mid;
}

double CTracker::intervalsIn(double seconds, double typical)
{
	// Whole intervals: a sensor runs at a fixed rate and its stamps jitter by a few ms (the host's
	// reception time), which must not scale a motion; a dropped frame is a whole interval.
	return typical > 0 && seconds > 0 ? std::max(1.0, std::round(seconds / typical)) : 1.0;
}

mrpt::poses::CPose3D CTracker::lastFramePose() const
{
	if (!last_) return {};
	// A bad reference still resolves: its pose follows its parent.
	return lastAnchor_.refKf ? lastAnchor_.poseIn(map_) : last_->pose;
}
}  // namespace mrpt_yesslam
