#include "mrpt_yesslam/system/CFrameRecords.h"

namespace mrpt_yesslam
{
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
			if (anchor) records_[i].anchor = *anchor;
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
	out.reserve(records.size());
	for (const auto& r : records)
	{
		if (!r.hasPose) continue;  // only before the first pose: what follows is in time order still
		// TAnchor::poseIn with the keyframe poses read once for the whole trajectory.
		const auto it = r.anchor.refKf ? keyFramePoses.find(*r.anchor.refKf) : keyFramePoses.end();
		out.push_back(TStampedPose::fromPose(r.t, it != keyFramePoses.end() ? it->second + r.anchor.relative : r.anchor.relative));
		tracked.push_back(r.tracked);
	}
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
