#include "mrpt_yesslam/feature/COrbMatcher.h"

#include "mrpt_yesslam/geometry/CPinholeCamera.h"

#include <cmath>
#include <cstring>

namespace mrpt_yesslam
{
int orbDistance(const unsigned char* a, const unsigned char* b)
{
	int d = 0;
	for (int k = 0; k < 4; k++)
	{
		std::uint64_t x, y;
		std::memcpy(&x, a + 8 * k, 8);
		std::memcpy(&y, b + 8 * k, 8);
		d += __builtin_popcountll(x ^ y);
	}
	return d;
}

namespace
{
// Keeps, of the matches sharing a keypoint (or a point: `key` picks which), only the closest: a
// point set may contain near-duplicates, and one keypoint observes one point.
std::vector<TMatch> uniqueBy(const std::vector<TMatch>& m, std::size_t n, std::size_t TMatch::*key)
{
	std::vector<int> best(n, -1);
	for (std::size_t i = 0; i < m.size(); i++)
	{
		int& b = best[m[i].*key];
		if (b < 0 || m[i].distance < m[static_cast<std::size_t>(b)].distance) b = static_cast<int>(i);
	}
	std::vector<TMatch> out;
	for (int b : best)
		if (b >= 0) out.push_back(m[static_cast<std::size_t>(b)]);
	return out;
}

}  // namespace

std::vector<TMatch> COrbMatcher::searchByProjection(const TFrame& frame, const mrpt::poses::CPose3D& Twc,
													const TLocalMapPoints& points, double radius,
													std::vector<std::size_t>* inView, bool skipMatched,
													double scaleFactor, bool viewChecks) const
{
	std::vector<TMatch> found;
	if (inView) inView->clear();
	const auto& kps = frame.features.keypoints;
	if (kps.empty() || points.ids.empty()) return found;
	// A coarse grid of keypoint indices, so each projection looks at a few cells only.
	const int cell = 16;
	const int W = static_cast<int>(frame.camera.ncols), H = static_cast<int>(frame.camera.nrows);
	const int gw = std::max(1, (W + cell - 1) / cell), gh = std::max(1, (H + cell - 1) / cell);
	std::vector<std::vector<int>> grid(static_cast<std::size_t>(gw * gh));
	int maxOctave = 0;
	for (std::size_t i = 0; i < kps.size(); i++)
	{
		if (frame.features.dynamic[i]) continue;
		maxOctave = std::max(maxOctave, std::clamp(kps[i].octave, 0, 15));
		if (skipMatched && i < frame.mapPoints.size() && frame.mapPoints[i] >= 0) continue;
		const int gx = std::clamp(static_cast<int>(kps[i].pt.x) / cell, 0, gw - 1);
		const int gy = std::clamp(static_cast<int>(kps[i].pt.y) / cell, 0, gh - 1);
		grid[static_cast<std::size_t>(gy * gw + gx)].push_back(static_cast<int>(i));
	}
	// The pyramid's reach is the extractor's, not the frame's highest keypoint: a frame whose
	// coarse levels found nothing (blur, a close wall) still sees a near point at its coarse level,
	// and calling it out of view would count it as missed (countTracking).
	if (frame.features.levels > 0) maxOctave = std::clamp(frame.features.levels - 1, 0, 15);
	const mrpt::poses::CPose3D Tcw = -Twc;
	const CPinholeCamera K(frame.camera);
	std::vector<double> levelScale(16, 1.0);
	for (std::size_t l = 1; l < levelScale.size(); l++) levelScale[l] = levelScale[l - 1] * scaleFactor;
	const bool views = viewChecks && points.hasViews();
	const double logScale = std::log(scaleFactor);
	for (std::size_t j = 0; j < points.ids.size(); j++)
	{
		double x, y, z;
		const auto& P = points.positions[j];
		Tcw.composePoint(P.x, P.y, P.z, x, y, z);
		double u, v;
		if (z < 0.05 || !K.project(x, y, z, u, v) || u < 0 || v < 0 || u >= W || v >= H) continue;
		// ORB-SLAM2's Frame::isInFrustum and MapPoint::PredictScale: a keypoint seen at level l from
		// distance d is found from d * scale^l (level 0) down to that over the pyramid's reach; a
		// descriptor does not survive a view more than 60 degrees off the ones it was seen from.
		int levelLo = 0, levelHi = maxOctave;
		if (views)
		{
			const double dx = P.x - Twc.x(), dy = P.y - Twc.y(), dz = P.z - Twc.z();
			const double dist = std::sqrt(dx * dx + dy * dy + dz * dz);
			const double maxD =
				points.refDistances[j] * levelScale[static_cast<std::size_t>(std::clamp(points.refOctaves[j], 0, 15))];
			const double minD = maxD / levelScale[static_cast<std::size_t>(maxOctave)];
			if (!(dist > 0) || dist < 0.8 * minD || dist > 1.2 * maxD) continue;
			const auto& n = points.normals[j];
			if ((dx * n.x + dy * n.y + dz * n.z) / dist < 0.5) continue;
			levelHi = std::clamp(static_cast<int>(std::ceil(std::log(maxD / dist) / logScale)), 0, maxOctave);
			levelLo = std::max(0, levelHi - 1);
		}
		if (inView) inView->push_back(j);
		const unsigned char* d = points.descriptors.ptr<unsigned char>(static_cast<int>(j));
		TBestTwo two;
		// The cells to scan: as far as the coarsest level searched reaches.
		const double rMax = radius * levelScale[static_cast<std::size_t>(levelHi)];
		const int x0 = std::max(0, static_cast<int>((u - rMax) / cell)),
				  x1 = std::min(gw - 1, static_cast<int>((u + rMax) / cell));
		const int y0 = std::max(0, static_cast<int>((v - rMax) / cell)),
				  y1 = std::min(gh - 1, static_cast<int>((v + rMax) / cell));
		for (int gy = y0; gy <= y1; gy++)
			for (int gx = x0; gx <= x1; gx++)
				for (int i : grid[static_cast<std::size_t>(gy * gw + gx)])
				{
					const auto& kp = kps[static_cast<std::size_t>(i)];
					if (views && (kp.octave < levelLo || kp.octave > levelHi)) continue;
					// ORB-SLAM scales the window with the keypoint's pyramid level (with the
					// predicted level, with that one).
					const double r =
						radius * levelScale[static_cast<std::size_t>(views ? levelHi : std::clamp(kp.octave, 0, 15))];
					const double du = kp.pt.x - u, dv = kp.pt.y - v;
					if (du * du + dv * dv > r * r) continue;
					two.add(orbDistance(d, frame.features.descriptors.ptr<unsigned char>(i)), i);
				}
		if (two.accepted(maxDist_, ratio_)) found.push_back({static_cast<std::size_t>(two.index), j, two.best});
	}
	return uniqueBy(found, kps.size(), &TMatch::keypoint);
}

std::vector<TMatch> COrbMatcher::matchBruteForce(const TFrame& frame, const cv::Mat& pointDescriptors) const
{
	std::vector<TMatch> found;
	const auto& F = frame.features;
	if (pointDescriptors.empty() || F.descriptors.empty()) return found;
	for (std::size_t i = 0; i < F.keypoints.size(); i++)
	{
		if (F.dynamic[i]) continue;
		const unsigned char* d = F.descriptors.ptr<unsigned char>(static_cast<int>(i));
		TBestTwo two;
		for (int j = 0; j < pointDescriptors.rows; j++)
			two.add(orbDistance(d, pointDescriptors.ptr<unsigned char>(j)), j);
		if (two.accepted(maxDist_, ratio_)) found.push_back({i, static_cast<std::size_t>(two.index), two.best});
	}
	// One keypoint per point as well.
	return uniqueBy(found, static_cast<std::size_t>(pointDescriptors.rows), &TMatch::point);
}
}  // namespace mrpt_yesslam
