#include "mrpt_yesslam/system/CFrameRecords.h"

#include <mrpt/poses/Lie/SE.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <optional>

namespace mrpt_yesslam
{
namespace
{
// The frames whose poses a frame's fit uses: k itself, then the `window` nearest `lends` frames on
// each side; stretches (CFrameRecords::trajectory: a generation of the map, up to a relocalisation)
// only grow, so the first frame of another one ends a side, and so does a frame `stop` flags (null:
// none).
std::vector<std::size_t> neighbours(std::size_t k, const std::vector<bool>& lends,
									const std::vector<std::uint64_t>& stretch, int window,
									const std::vector<bool>* stop = nullptr)
{
	std::vector<std::size_t> out{k};
	const std::size_t n = lends.size();
	for (const int dir : {-1, 1})
	{
		int found = 0;
		for (std::size_t j = k; found < window;)
		{
			if (dir < 0 ? j == 0 : j + 1 >= n) break;
			j = dir < 0 ? j - 1 : j + 1;
			if (stretch[j] != stretch[k] || (stop && (*stop)[j])) break;
			if (lends[j])
			{
				out.push_back(j);
				found++;
			}
		}
	}
	return out;
}

// The `averaged` frames' poses replaced by `smoothed`. A coasted pose after an averaged one keeps
// its step from it: moved with it, not left behind (the frames a run ends on while lost); one on
// its fallback (`anchored` false) has no step to keep, and one after a tracked frame that was not
// averaged (pinned, or keyframe-less) is that frame's.
void replaceAveraged(TTrajectory& out, const std::vector<mrpt::poses::CPose3D>& smoothed,
					 const std::vector<bool>& averaged, const std::vector<bool>& tracked,
					 const std::vector<bool>& anchored)
{
	constexpr std::size_t none = static_cast<std::size_t>(-1);
	std::size_t last = none;  // the latest averaged frame, for the coasted ones after it
	mrpt::poses::CPose3D lastBefore;
	for (std::size_t k = 0; k < out.size(); k++)
	{
		if (averaged[k])
		{
			last = k;
			lastBefore = out[k].asPose();
			out[k] = TStampedPose::fromPose(out[k].t, smoothed[k]);
		}
		else if (tracked[k])
			last = none;
		else if (last != none && anchored[k])
			out[k] = TStampedPose::fromPose(out[k].t, smoothed[last] + (out[k].asPose() - lastBefore));
	}
}

// Each averaged pose's correction (final = correction + online) replaced by the mean of the
// corrections of the lending poses within `window` of it (one stretch), in the tangent space at
// its own. A tracked pose lends when it hangs from a keyframe the map still has (`anchored`: a
// record whose keyframe went keeps its fallback and lends it to nobody), and is averaged when it
// also is not `pinned` to its own keyframe (it is that keyframe's, and lends that correction).
void smoothCorrections(TTrajectory& out, const std::vector<bool>& tracked, const std::vector<bool>& anchored,
					   const std::vector<bool>& pinned, const std::vector<mrpt::poses::CPose3D>& online,
					   const std::vector<std::uint64_t>& stretch, int window)
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
		const auto near = neighbours(k, lends, stretch, window);
		for (const std::size_t j : near)
		{
			const auto d = mrpt::poses::Lie::SE<3>::log(corr[j] - corr[k]);
			for (int i = 0; i < 6; i++) mean[i] += d[i];
		}
		for (int i = 0; i < 6; i++) mean[i] /= static_cast<double>(near.size());
		smoothed[k] = corr[k] + mrpt::poses::Lie::SE<3>::exp(mean) + online[k];
	}
	replaceAveraged(out, smoothed, averaged, tracked, anchored);
}

// Each averaged frame's position replaced by the value at its stamp of a parabola fitted in time through the positions
// of the lending frames around it: as many on each side, up to `window` (a one-sided fit at a run's ends would
// extrapolate). A parabola, not a line: a camera that speeds up or turns back keeps its corners (a line cut those of a
// fast simulated camera). A side ends at another stretch, at a frame tracking lost (the camera may have turned back
// unseen; a relocalised pose may jump against the drift before the loss) and beyond window / 15 s, twice the time the
// window spans at 30 Hz (frames a live run dropped); so the two tracked frames either side of a loss stay as solved,
// and the lost ones with them. The orientation stays the frame's own: a single frame fixes it well, and the real
// hand-held cameras turn back and forth faster than they move (a parabola through the orientations too made the
// rotation errors of the real Bonn slice and the real fr1/xyz path larger). Lending and smoothed frames as the lending
// and averaged ones of smoothCorrections.
void smoothMotion(TTrajectory& out, const std::vector<bool>& tracked, const std::vector<bool>& anchored,
				  const std::vector<bool>& pinned, const std::vector<std::uint64_t>& stretch, int window)
{
	const std::size_t n = out.size();
	std::vector<bool> lends(n), untracked(n);
	for (std::size_t k = 0; k < n; k++)
	{
		// Stamps in microseconds must fit a long long (seconds since 1970 do, by far).
		lends[k] = tracked[k] && anchored[k] && std::isfinite(out[k].t) && std::abs(out[k].t) < 1e12;
		untracked[k] = !tracked[k];
	}
	const double span = window / 15.0;  // seconds: twice the window at 30 Hz
	// Times in whole microseconds, as the trajectory files and .oni recordings keep the stamps: a
	// run replayed from its own recording gives the same poses to the last digit. Rounded once.
	std::vector<long long> us(n, 0);
	for (std::size_t k = 0; k < n; k++)
		if (lends[k]) us[k] = std::llround(out[k].t * 1e6);
	std::vector<std::optional<Eigen::Vector3d>> shift(n);
	for (std::size_t k = 0; k < n; k++)
	{
		if (!lends[k] || pinned[k]) continue;
		const auto since = [&](std::size_t j) { return 1e-6 * static_cast<double>(us[j] - us[k]); };
		// neighbours() lists k, then the earlier frames nearest first, then the later ones.
		auto near = neighbours(k, lends, stretch, window, &untracked);
		near.erase(std::remove_if(near.begin() + 1, near.end(),
								  [&](std::size_t j) { return std::abs(out[j].t - out[k].t) > span; }),
				   near.end());
		std::size_t before = 0;
		while (1 + before < near.size() && near[1 + before] < k) before++;
		const std::size_t after = near.size() - 1 - before, side = std::min(before, after);
		if (side < 2) continue;  // a parabola through three positions is the position itself
		std::vector<std::size_t> used{k};
		for (std::size_t i = 0; i < side; i++)
		{
			used.push_back(near[1 + i]);
			used.push_back(near[1 + before + i]);
		}
		// Least squares of p_j = a + b s_j + c s_j^2 (s_j the time from frame k): a = e0' (X'X)^-1 X' p.
		// It needs three different times (a rawlog without stamps gives every frame the same one).
		Eigen::Matrix3d XtX = Eigen::Matrix3d::Zero();
		std::vector<double> times;  // s_j, in the order of `used`
		for (const std::size_t j : used)
		{
			const double sj = since(j);
			times.push_back(sj);
			const Eigen::Vector3d x(1, sj, sj * sj);
			XtX += x * x.transpose();
		}
		std::vector<double> sorted = times;
		// Frame k's moment inside the fitted times, not at their edge (repeated stamps).
		std::sort(sorted.begin(), sorted.end());
		if (std::unique(sorted.begin(), sorted.end()) - sorted.begin() < 3 ||
			!(sorted.front() < 0 && sorted.back() > 0))
			continue;
		const Eigen::Vector3d row = XtX.ldlt().solve(Eigen::Vector3d::UnitX());  // (X'X)^-1 e0 (symmetric)
		if (!row.allFinite()) continue;
		// Relative to frame k's own position: the sums stay small whatever the map's extent.
		Eigen::Vector3d a = Eigen::Vector3d::Zero();
		for (std::size_t i = 0; i < used.size(); i++)
		{
			const std::size_t j = used[i];
			const double sj = times[i];
			a += (row[0] + row[1] * sj + row[2] * sj * sj) *
				 Eigen::Vector3d(out[j].tx - out[k].tx, out[j].ty - out[k].ty, out[j].tz - out[k].tz);
		}
		if (a.allFinite()) shift[k] = a;
	}
	// Applied after every fit (each fit reads the positions as solved), to the position alone, so
	// the orientations stay what they were to the bit.
	for (std::size_t k = 0; k < n; k++)
		if (shift[k])
		{
			out[k].tx += (*shift[k])[0];
			out[k].ty += (*shift[k])[1];
			out[k].tz += (*shift[k])[2];
		}
}
}  // namespace

CFrameRecords::TPoseRT CFrameRecords::TPoseRT::of(const mrpt::poses::CPose3D& p)
{
	TPoseRT out;
	const auto& R = p.getRotationMatrix();
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++) out.v[3 * r + c] = R(r, c);
	out.v[9] = p.x(), out.v[10] = p.y(), out.v[11] = p.z();
	return out;
}

mrpt::poses::CPose3D CFrameRecords::TPoseRT::pose() const
{
	mrpt::math::CMatrixDouble33 R;
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++) R(r, c) = v[3 * r + c];
	return mrpt::poses::CPose3D(R, mrpt::math::CVectorFixedDouble<3>({v[9], v[10], v[11]}));
}

CFrameRecords::TStored CFrameRecords::TStored::of(const TRecord& r)
{
	TStored s;
	s.t = r.t;
	s.refKf = r.anchor.refKf;
	s.relative = TPoseRT::of(r.anchor.relative);
	s.online = TPoseRT::of(r.online);
	s.measured = TPoseRT::of(r.measured);
	s.generation = r.generation;
	s.tracked = r.tracked, s.hasPose = r.hasPose, s.jumped = r.jumped, s.pinned = r.pinned;
	return s;
}

CFrameRecords::TRecord CFrameRecords::TStored::record() const
{
	TRecord r;
	r.t = t;
	r.anchor.refKf = refKf;
	r.anchor.relative = relative.pose();
	r.online = online.pose();
	r.measured = measured.pose();
	r.generation = generation;
	r.tracked = tracked, r.hasPose = hasPose, r.jumped = jumped, r.pinned = pinned;
	return r;
}

void CFrameRecords::add(const TRecord& record, const TFrameLogRow& row)
{
	std::lock_guard<std::mutex> lk(mtx_);
	records_.push_back(TStored::of(record));
	rows_.push_back(row);
}

void CFrameRecords::markKeyFrame(std::size_t frame, const std::optional<TAnchor>& anchor)
{
	std::lock_guard<std::mutex> lk(mtx_);
	for (std::size_t i = rows_.size(); i-- > 0;)
		if (rows_[i].frame == frame)
		{
			rows_[i].keyFrame = true;
			if (anchor)
			{
				records_[i].refKf = anchor->refKf;
				records_[i].relative = TPoseRT::of(anchor->relative);
				records_[i].pinned = true;
			}
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

CFrameRecords::TCarried CFrameRecords::carried(
	const std::function<std::map<TKeyFrameId, mrpt::poses::CPose3D>()>& poses) const
{
	std::vector<TStored> records;
	std::vector<bool> relocalised;
	{
		std::lock_guard<std::mutex> lk(mtx_);
		records.assign(records_.begin(), records_.end());
		for (const auto& row : rows_) relocalised.push_back(row.relocalised);
	}
	const std::map<TKeyFrameId, mrpt::poses::CPose3D> keyFramePoses = poses();
	TCarried c;
	std::uint64_t generation = 0;  // the previous record's
	// The stretches smoothed() stays within: a loop correction or a global BA (a new generation)
	// ends one, and so does a relocalised frame: the step onto it is where tracking had drifted,
	// not the camera's motion (a fit through it spread the jump over the frames either side); and
	// a jerk, which a parabola through it would spread the same way.
	c.poses.reserve(records.size());
	for (std::size_t i = 0; i < records.size(); i++)
	{
		if (!records[i].hasPose) continue;  // only before the first pose: what follows is in time order still
		const TRecord r = records[i].record();
		const bool newStretch = !c.stretch.empty() &&
								(r.generation != generation || (i < relocalised.size() && relocalised[i]) || r.jumped);
		c.stretch.push_back(c.stretch.empty() ? 0 : c.stretch.back() + (newStretch ? 1 : 0));
		generation = r.generation;
		// TAnchor::poseIn with the keyframe poses read once for the whole trajectory.
		const auto it = r.anchor.refKf ? keyFramePoses.find(*r.anchor.refKf) : keyFramePoses.end();
		c.poses.push_back(TStampedPose::fromPose(
			r.t, it != keyFramePoses.end() ? it->second + r.anchor.relative : r.anchor.relative));
		c.tracked.push_back(r.tracked);
		c.online.push_back(r.measured);
		c.anchored.push_back(!r.anchor.refKf || it != keyFramePoses.end());
		c.pinned.push_back(r.pinned);
	}
	return c;
}

TTrajectory CFrameRecords::trajectory(const std::function<std::map<TKeyFrameId, mrpt::poses::CPose3D>()>& poses) const
{
	return carried(poses).poses;
}

TTrajectory CFrameRecords::smoothed(const std::function<std::map<TKeyFrameId, mrpt::poses::CPose3D>()>& poses) const
{
	TCarried c = carried(poses);
	TTrajectory& out = c.poses;
	// A frame hangs from the keyframe it was tracked against, and consecutive frames often from
	// different ones, which mapping moved differently since (above all in parallel mode, where a
	// keyframe's local BA lands frames after it): the steps between such frames carry the
	// difference, not the camera's motion. What mapping moved a frame by changes slowly along the
	// path, so it is averaged over a few frames either side and applied to the pose tracking
	// measured. Never across a loop correction or a global BA (a new generation: those frames were
	// tracked in another map), or a relocalisation.
	if (correctionWindow_ > 0)
		smoothCorrections(out, c.tracked, c.anchored, c.pinned, c.online, c.stretch, correctionWindow_);
	// Each tracked pose is a solve of its own frame's keypoints, whose noise makes the path zig-zag
	// around the camera's; a camera's motion is smooth over a few frames, so the position is the
	// value at its stamp of a parabola fitted in time through the nearest tracked frames either
	// side (a Savitzky-Golay smoother on the frames' own stamps, in the spirit of a fixed-interval
	// smoother). Never across a loop correction, a global BA, a relocalisation or a loss.
	if (smoothingWindow_ > 0) smoothMotion(out, c.tracked, c.anchored, c.pinned, c.stretch, smoothingWindow_);
	// Lost frames a relocalisation ended: between the two tracked poses around them (from the
	// keyframes' current poses, so later corrections carry over) rather than the coasted guess,
	// which drifts away wherever the camera did not keep its last velocity. poseSources() names them.
	if (lostInterpolate_) interpolateUntracked(out, c.tracked);
	return out;
}

TTrajectory CFrameRecords::online() const
{
	std::lock_guard<std::mutex> lk(mtx_);
	TTrajectory out;
	out.reserve(records_.size());
	for (const auto& r : records_)
		if (r.hasPose) out.push_back(TStampedPose::fromPose(r.t, r.online.pose()));
	return out;
}

std::vector<TFrameLogRow> CFrameRecords::frameLog() const
{
	std::lock_guard<std::mutex> lk(mtx_);
	std::vector<TFrameLogRow> rows(rows_.begin(), rows_.end());
	const auto src = poseSources();
	for (std::size_t i = 0; i < rows.size() && i < src.size(); i++) rows[i].pose = src[i];
	return rows;
}

CFrameRecords::TSince CFrameRecords::since(std::size_t first) const
{
	std::lock_guard<std::mutex> lk(mtx_);
	TSince out;
	for (std::size_t i = first; i < records_.size(); i++)
	{
		const TStored& r = records_[i];
		out.rows.push_back(rows_[i]);
		out.rows.back().pose = !r.hasPose ? EPoseSource::None : r.tracked ? EPoseSource::Tracked : EPoseSource::Coasted;
		if (r.hasPose) out.online.push_back(TStampedPose::fromPose(r.t, r.online.pose()));
	}
	return out;
}
}  // namespace mrpt_yesslam
