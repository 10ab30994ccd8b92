#include "mrpt_yesslam/optimize/PointFusion.h"

#include <cmath>

#include "mrpt_yesslam/feature/COrbMatcher.h"

namespace mrpt_yesslam
{
std::vector<TFuseCandidate> fuseCandidates(const CKeyFrame& into, const mrpt::poses::CPose3D& Twc,
										   const TLocalMapPoints& pts, double radius, int maxHamming,
										   double scaleFactor, const TDepthNoise& depthNoise)
{
	std::vector<TFuseCandidate> cands;
	if (pts.ids.empty() || !into.features) return cands;
	TFrame f;  // the keyframe's measurements as the matcher takes them
	f.id = into.frameId;
	f.camera = into.camera;
	f.features = *into.features;
	f.mapPoints = into.mapPoints;
	const COrbMatcher matcher(maxHamming, 1.0);
	const mrpt::poses::CPose3D Tcw = -Twc;
	for (const TMatch& m : matcher.searchByProjection(f, Twc, pts, radius, nullptr, false, scaleFactor))
	{
		const float d = f.features.depth[m.keypoint];
		if (d > 0)
		{
			const auto& P = pts.positions[m.point];
			double x, y, z;
			Tcw.composePoint(P.x, P.y, P.z, x, y, z);
			if (std::abs(d - z) > 0.02 + 3 * depthNoise.sigma(z)) continue;
		}
		cands.push_back({pts.ids[m.point], into.id, m.keypoint});
	}
	return cands;
}
}  // namespace mrpt_yesslam
