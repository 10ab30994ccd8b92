#include "mrpt_yesslam/keyframes/CKeyFrameInserter.h"

#include <mrpt/config/CConfigFileBase.h>

#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
void CKeyFrameInserter::TOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	semantic.loadFromConfigFile(c, s);
	MRPT_LOAD_CONFIG_VAR(policy, string, c, s);
	MRPT_LOAD_CONFIG_VAR(forceTrackedRatio, double, c, s);
	MRPT_LOAD_CONFIG_VAR(orbMaxFrames, int, c, s);
	MRPT_LOAD_CONFIG_VAR(orbMinFrames, int, c, s);
	MRPT_LOAD_CONFIG_VAR(orbRefRatio, double, c, s);
	MRPT_LOAD_CONFIG_VAR(closeDepth, double, c, s);
}

void CKeyFrameInserter::TOptions::dumpToTextStream(std::ostream& o) const
{
	semantic.dumpToTextStream(o);
	o << "policy            = " << policy << "\n";
	o << "forceTrackedRatio = " << forceTrackedRatio << "\n";
	o << "orbMaxFrames      = " << orbMaxFrames << "\n";
	o << "orbMinFrames      = " << orbMinFrames << "\n";
	o << "orbRefRatio       = " << orbRefRatio << "\n";
	o << "closeDepth        = " << closeDepth << "\n";
}

std::vector<TConfigKey> CKeyFrameInserter::TOptions::configKeys()
{
	using T = TConfigKey::Type;
	auto k = CSemanticKeyFrameSelector::TOptions::configKeys();
	for (const auto& e : std::vector<TConfigKey>{
			 {"policy", T::Text},
			 {"forceTrackedRatio", T::Number},
			 {"orbMaxFrames", T::Integer},
			 {"orbMinFrames", T::Integer},
			 {"orbRefRatio", T::Number},
			 {"closeDepth", T::Number}})
		k.push_back(e);
	return k;
}

CKeyFrameInserter::CKeyFrameInserter(const TOptions& opts) : opts_(opts), selector_(opts.semantic)
{
	if (opts_.policy != "semantic" && opts_.policy != "orbslam")
		throw InputError("", "[KeyFrames] policy must be semantic or orbslam, not '" + opts_.policy + "'");
	if (!(opts_.forceTrackedRatio >= 0 && opts_.forceTrackedRatio < 1))
		throw InputError("", "[KeyFrames] forceTrackedRatio must be in [0,1)");
	if (opts_.orbMaxFrames < 1 || opts_.orbMinFrames < 0)
		throw InputError("", "[KeyFrames] orbMaxFrames must be >= 1 and orbMinFrames >= 0");
}

std::optional<CKeyFrameInserter::TDecision> CKeyFrameInserter::addFrame(const TFrame& f, const TReference& ref, double motion)
{
	if (!f.tracked) return std::nullopt;
	const double refPoints = static_cast<double>(std::max<std::size_t>(1, ref.points));
	const double inliers = static_cast<double>(f.numInliers);
	if (opts_.policy == "orbslam")
	{
		const std::size_t since = lastKeyFrame_ ? f.id - *lastKeyFrame_ : f.id + 1;
		std::size_t trackedClose = 0, untrackedClose = 0;
		for (std::size_t i = 0; i < f.size(); i++)
		{
			if (!f.usable(i, opts_.closeDepth)) continue;
			(f.mapPoints[i] >= 0 ? trackedClose : untrackedClose)++;
		}
		const bool needClose = trackedClose < 100 && untrackedClose > 70;
		const bool c1a = since >= static_cast<std::size_t>(opts_.orbMaxFrames);
		const bool c1b = since >= static_cast<std::size_t>(opts_.orbMinFrames);	// mapping is never busy here
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
		return TDecision{f.id, true};
	}
	if (const auto d = selector_.addFrame(in)) return TDecision{d->frameId, false};
	return std::nullopt;
}
}  // namespace mrpt_yesslam
