#include "mrpt_yesslam/feature/DepthMoment.h"

#include <cmath>

#include "mrpt_yesslam/feature/COrbExtractor.h"

namespace mrpt_yesslam
{
std::size_t moveDepthToColourMoment(TFeatures& f, const cv::Mat& depth, const CPinholeCamera& K,
									const mrpt::poses::CPose3D& depthCamera)
{
	std::size_t lost = 0;
	for (std::size_t i = 0; i < f.keypoints.size(); i++)
	{
		float& z = f.depth[i];
		if (!(z > 0)) continue;
		const cv::Point2f p = f.keypoints[i].pt;
		// Fixed point: the depth read at the point's place in the depth image moves the place a
		// little (only through translation; a rotation moves every depth alike), so two rounds
		// settle it to well under a millimetre.
		double zc = z;
		for (int round = 0; round < 2 && zc > 0; round++)
		{
			const cv::Point3d Xc = K.backProject(p.x, p.y, zc);
			mrpt::math::TPoint3D Xd;
			depthCamera.inverseComposePoint({Xc.x, Xc.y, Xc.z}, Xd);
			double u = 0, v = 0;
			if (!K.project(Xd.x, Xd.y, Xd.z, u, v))
			{
				zc = 0;
				break;
			}
			const cv::Point2d raw = K.distort(u, v);
			const double zd = COrbExtractor::depthAt(depth, raw.x, raw.y);
			if (!(zd > 0))
			{
				zc = 0;
				break;
			}
			// The surface point the depth image saw there, back at the colour image's moment.
			const double s = zd / Xd.z;
			mrpt::math::TPoint3D back;
			depthCamera.composePoint({Xd.x * s, Xd.y * s, Xd.z * s}, back);
			zc = back.z;
		}
		if (!(zc > 0)) lost++;
		z = zc > 0 ? static_cast<float>(zc) : 0.f;
	}
	return lost;
}
}  // namespace mrpt_yesslam
