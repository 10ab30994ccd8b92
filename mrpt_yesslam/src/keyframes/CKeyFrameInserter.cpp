#include "mrpt_yesslam/keyframes/CKeyFrameInserter.h"

#include <mrpt/config/CConfigFileBase.h>

#include "mrpt_yesslam/util/Error.h"

#include <algorithm>

namespace mrpt_yesslam
{
COptionTable CKeyFrameInserter::TOptions::table()
{
	COptionTable t("KeyFrames");
	t.append(semantic.table());
	t.text("policy", policy, "semantic: the paper's Algorithm 1; orbslam: ORB-SLAM2's NeedNewKeyFrame",
		   {"semantic", "orbslam"});
	t.real("forceTrackedRatio", forceTrackedRatio, 0, 0.999,
		   "semantic: insert at once when inliers fall below this share of the reference keyframe's points");
	t.real("semanticRefRatio", semanticRefRatio, 0.01, 1,
		   "semantic: Algorithm 1's choice is inserted only if it tracks fewer than this share of the reference's "
		   "points (1 = always)");
	t.text("motionReference", motionReference,
		   "semantic: D (eq. 12-17) against tracker (the keyframe sharing most points with the frame) or previous "
		   "(Algorithm 1's F_ref: the keyframe its last interval chose)",
		   {"tracker", "previous"});
	t.integer("orbMaxFrames", orbMaxFrames, 1, 100000,
			  "orbslam: a keyframe at least this often (ORB-SLAM2: the frame rate)");
	t.integer("orbMinFrames", orbMinFrames, 0, 100000, "orbslam: no keyframe sooner than this");
	t.real("orbRefRatio", orbRefRatio, 0, 1, "orbslam: c2 threshold on inliers / reference points");
	t.real("closeDepth", closeDepth, 0.1, 100,
		   "close points for the need-close-points test (ORB-SLAM2's ThDepth, 40 baselines), m");
	return t;
}

CKeyFrameInserter::CKeyFrameInserter(const TOptions& opts) : opts_(opts), selector_(opts.semantic)
{
	if (opts_.policy != "semantic" && opts_.policy != "orbslam")
		throw InputError("", "[KeyFrames] policy must be semantic or orbslam, not '" + opts_.policy + "'");
	if (!(opts_.forceTrackedRatio >= 0 && opts_.forceTrackedRatio < 1))
		throw InputError("", "[KeyFrames] forceTrackedRatio must be in [0,1)");
	if (opts_.motionReference != "tracker" && opts_.motionReference != "previous")
		throw InputError(
			"", "[KeyFrames] motionReference must be tracker or previous, not '" + opts_.motionReference + "'");
	if (!(opts_.semanticRefRatio > 0 && opts_.semanticRefRatio <= 1))
		throw InputError("", "[KeyFrames] semanticRefRatio must be in (0,1]");
	if (opts_.orbMaxFrames < 1 || opts_.orbMinFrames < 0)
		throw InputError("", "[KeyFrames] orbMaxFrames must be >= 1 and orbMinFrames >= 0");
}

bool CKeyFrameInserter::needsClosePoints(const TFrame& f) const
{
	std::size_t trackedClose = 0, untrackedClose = 0;
	for (std::size_t i = 0; i < f.size(); i++)
	{
		if (!f.usable(i, opts_.closeDepth)) continue;
		(i < f.mapPoints.size() && f.mapPoints[i] >= 0 ? trackedClose : untrackedClose)++;
	}
	return trackedClose < 100 && untrackedClose > 70;
}

std::optional<CKeyFrameInserter::TDecision> CKeyFrameInserter::addFrame(const TFrame& f, const TReference& ref,
																		double motion)
{
	if (!f.tracked) return std::nullopt;
	const double refPoints = static_cast<double>(std::max<std::size_t>(1, ref.points));
	const double inliers = static_cast<double>(f.numInliers);
	if (opts_.policy == "orbslam")
	{
		const std::size_t since = lastKeyFrame_ ? f.id - *lastKeyFrame_ : f.id + 1;
		const bool needClose = needsClosePoints(f);
		const bool c1a = since >= static_cast<std::size_t>(opts_.orbMaxFrames);
		const bool c1b = since >= static_cast<std::size_t>(opts_.orbMinFrames);  // mapping is never busy here
		const bool c1c = inliers < 0.25 * refPoints || needClose;
		const bool c2 = (inliers < opts_.orbRefRatio * refPoints || needClose) && f.numInliers > 15;
		if ((c1a || c1b || c1c) && c2) return TDecision{f.id, false};
		return std::nullopt;
	}
	TKeyFrameInput in;
	in.frameId = f.id;
	in.detections = f.detections;
	in.imageSize = cv::Size(static_cast<int>(f.camera.ncols), static_cast<int>(f.camera.nrows));
	in.numFeatures = f.size();
	in.numStatic = f.features.numStatic();
	in.numInliers = f.numInliers;
	in.motion = motion;
	if (inliers < opts_.forceTrackedRatio * refPoints && f.numInliers > 15)
	{
		// The forced keyframe becomes the selector's reference and opens a new interval: a frame of
		// the interval it cut short must not become a keyframe after it (ids would leave time order).
		selector_.restart(in);
		coverage_.clear();
		return TDecision{f.id, true};
	}
	// Judged now, while `ref` is the reference this frame was tracked against.
	// (The selector's first choice, its first reference, is not judged: there is no map yet.)
	const bool first = !selector_.referenceId();
	coverage_.push_back({f.id, first || inliers < opts_.semanticRefRatio * refPoints || needsClosePoints(f)});
	const auto d = selector_.addFrame(in);
	if (!d)
	{
		// Only the open interval's frames can be chosen (the selector restarts with each interval).
		while (coverage_.size() >
			   static_cast<std::size_t>(std::max(opts_.semantic.interval, opts_.semantic.shortInterval)) * 2)
			coverage_.pop_front();
		return std::nullopt;
	}
	const auto it =
		std::find_if(coverage_.begin(), coverage_.end(), [&](const TCoverage& c) { return c.frameId == d->frameId; });
	const bool seesNew = it == coverage_.end() || it->seesNewContent;
	coverage_.clear();
	if (!seesNew)
	{
		redundantChoices_++;
		return std::nullopt;
	}
	return TDecision{d->frameId, false};
}
}  // namespace mrpt_yesslam
