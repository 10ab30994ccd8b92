#include "mrpt_yesslam/system/CFrameRecords.h"

#include <mrpt/poses/Lie/SE.h>

#include <algorithm>
#include <optional>

namespace mrpt_yesslam
{
namespace
{
// Each averaged pose's correction (final = correction + online) replaced by the mean of the
// corrections of the lending poses within `window` of it (one generation), in the tangent space at
// its own. A tracked pose lends when it hangs from a keyframe the map still has (`anchored`: a
// record whose keyframe went keeps its fallback and lends it to nobody), and is averaged when it
// also is not `pinned` to its own keyframe (it is that keyframe's, and lends that correction).
// A coasted pose after an averaged one keeps its step from it: moved with it, not left behind at
// its own unaveraged correction (the frames a run ends on while lost).
void smoothCorrections(
	TTrajectory& out, const std::vector<bool>& tracked, const std::vector<bool>& anchored, const std::vector<bool>& pinned,
	const std::vector<mrpt::poses::CPose3D>& online, const std::vector<std::uint64_t>& generation, int window)
{
	const std::size_t n = out.size();
	std::vector<bool> lends(n), averaged(n);
	for (std::size_t k = 0; k < n; k++)
	{
		lends[k] = tracked[k] && anchored[k];
		averaged[k] = lends[k] && !pinned[k];
	}
	std::vector<mrpt::poses::CPose3D> corr(n);
	for (std::size_t k = 0; k < n; k++)
		if (lends[k]) corr[k] = out[k].asPose() + (-online[k]);
	std::vector<mrpt::poses::CPose3D> smoothed(n);
	for (std::size_t k = 0; k < n; k++)
	{
		if (!averaged[k]) continue;
		mrpt::math::CVectorFixedDouble<6> mean;
		mean.setZero();
		double m = 0;
		const auto add = [&](std::size_t j)
		{
			const auto d = mrpt::poses::Lie::SE<3>::log(corr[j] - corr[k]);
			for (int i = 0; i < 6; i++) mean[i] += d[i];
			m += 1;
		};
		add(k);
		// The nearest `window` lending frames on each side; generations only grow, so the first
		// frame of another one ends the side.
		for (const int dir : {-1, 1})
		{
			int found = 0;
			for (std::size_t j = k; found < window;)
			{
				if (dir < 0 ? j == 0 : j + 1 >= n) break;
				j = dir < 0 ? j - 1 : j + 1;
				if (generation[j] != generation[k]) break;
				if (lends[j])
				{
					add(j);
					found++;
				}
			}
		}
		for (int i = 0; i < 6; i++) mean[i] /= m;
		smoothed[k] = corr[k] + mrpt::poses::Lie::SE<3>::exp(mean) + online[k];
	}
	std::optional<std::size_t> last;  // the latest averaged frame, for the coasted ones after it
	mrpt::poses::CPose3D lastBefore;
	for (std::size_t k = 0; k < n; k++)
	{
		if (averaged[k])
		{
			last = k;
			lastBefore = out[k].asPose();
			out[k] = TStampedPose::fromPose(out[k].t, smoothed[k]);
		}
		else if (tracked[k])
			last.reset();  // a pinned or keyframe-less tracked frame: coasting after it is its own
		else if (last && anchored[k])  // a coasted pose on its fallback has no step to keep
			out[k] = TStampedPose::fromPose(out[k].t, smoothed[*last] + (out[k].asPose() - lastBefore));
	}
}
}  // namespace

void CFrameRecords::add(const TRecord& record, const TFrameLogRow& row)
{
	std::lock_guard<std::mutex> lk(mtx_);
	records_.push_back(record);
	rows_.push_back(row);
}

void CFrameRecords::markKeyFrame(std::size_t frame, const std::optional<TAnchor>& anchor)
{
	std::lock_guard<std::mutex> lk(mtx_);
	for (std::size_t i = rows_.size(); i-- > 0;)
		if (rows_[i].frame == frame)
		{
			rows_[i].keyFrame = true;
			if (anchor) records_[i].pinTo(*anchor);
			return;
		}
}

std::vector<EPoseSource> CFrameRecords::poseSources() const
{
	std::vector<EPoseSource> out(records_.size(), EPoseSource::None);
	std::optional<std::size_t> lastTracked;
	for (std::size_t i = 0; i < records_.size(); i++)
	{
		if (!records_[i].hasPose) continue;
		if (!records_[i].tracked)
		{
			out[i] = EPoseSource::Coasted;
			continue;
		}
		out[i] = EPoseSource::Tracked;
		// The lost frames since the previous tracked one are filled in between the two (interpolateUntracked).
		if (lostInterpolate_ && lastTracked)
			for (std::size_t k = *lastTracked + 1; k < i; k++) out[k] = EPoseSource::Interpolated;
		lastTracked = i;
	}
	return out;
}

TTrajectory CFrameRecords::trajectory(const std::function<std::map<TKeyFrameId, mrpt::poses::CPose3D>()>& poses) const
{
	std::vector<TRecord> records;
	{
		std::lock_guard<std::mutex> lk(mtx_);
		records = records_;
	}
	const std::map<TKeyFrameId, mrpt::poses::CPose3D> keyFramePoses = poses();
	TTrajectory out;
	std::vector<bool> tracked;
	std::vector<mrpt::poses::CPose3D> online;
	std::vector<std::uint64_t> generation;
	std::vector<bool> anchored, pinned;
	out.reserve(records.size());
	for (const auto& r : records)
	{
		if (!r.hasPose) continue;  // only before the first pose: what follows is in time order still
		// TAnchor::poseIn with the keyframe poses read once for the whole trajectory.
		const auto it = r.anchor.refKf ? keyFramePoses.find(*r.anchor.refKf) : keyFramePoses.end();
		out.push_back(TStampedPose::fromPose(r.t, it != keyFramePoses.end() ? it->second + r.anchor.relative : r.anchor.relative));
		tracked.push_back(r.tracked);
		online.push_back(r.online);
		generation.push_back(r.generation);
		anchored.push_back(!r.anchor.refKf || it != keyFramePoses.end());
		pinned.push_back(r.pinned);
	}
	// A frame hangs from the keyframe it was tracked against, and consecutive frames often from
	// different ones, which mapping moved differently since (above all in parallel mode, where a
	// keyframe's local BA lands frames after it): the steps between such frames carry the
	// difference, not the camera's motion. What mapping moved a frame by changes slowly along the
	// path, so it is averaged over a few frames and applied to the pose tracking measured
	// (trajectory_online.txt), whose steps are the camera's. Never across a loop correction or a
	// global BA (a new generation: those frames were tracked in another map).
	if (correctionWindow_ > 0) smoothCorrections(out, tracked, anchored, pinned, online, generation, correctionWindow_);
	// Lost frames a relocalisation ended: between the two tracked poses around them (from the
	// keyframes' current poses, so later corrections carry over) rather than the coasted guess
	// written while lost, which drifts away wherever the camera did not keep its last velocity.
	// poseSources() names them; online() keeps what the robot had.
	if (lostInterpolate_) interpolateUntracked(out, tracked);
	return out;
}

TTrajectory CFrameRecords::online() const
{
	std::lock_guard<std::mutex> lk(mtx_);
	TTrajectory out;
	out.reserve(records_.size());
	for (const auto& r : records_)
		if (r.hasPose) out.push_back(TStampedPose::fromPose(r.t, r.online));
	return out;
}

std::vector<TFrameLogRow> CFrameRecords::frameLog() const
{
	std::lock_guard<std::mutex> lk(mtx_);
	std::vector<TFrameLogRow> rows = rows_;
	const auto src = poseSources();
	for (std::size_t i = 0; i < rows.size() && i < src.size(); i++) rows[i].pose = src[i];
	return rows;
}
}  // namespace mrpt_yesslam
