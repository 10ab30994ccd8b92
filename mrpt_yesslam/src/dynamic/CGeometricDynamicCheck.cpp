#include "mrpt_yesslam/dynamic/CGeometricDynamicCheck.h"

namespace mrpt_yesslam
{
COptionTable CGeometricDynamicCheck::TOptions::table()
{
	COptionTable t("GeometricCheck");
	t.flag("enabled", enabled, "keypoints in a dynamic box but outside its mask join the pose only if they agree with the pose from the others");
	t.real("boxMargin", boxMargin, 0, 1, "a dynamic box grows by this share of its size on every side");
	t.count("minCertainInliers", minCertainInliers, 4, 100000, "fewer inliers outside every dynamic box: the check stands aside for the frame");
	return t;
}

void CGeometricDynamicCheck::classify(TFeatures& f, const std::vector<TDetection>& detections, const cv::Size& image) const
{
	f.uncertain.assign(f.keypoints.size(), false);
	if (!opts_.enabled) return;
	std::vector<cv::Rect2f> boxes;
	for (const auto& d : detections)
		if (d.dynamic)
		{
			const float mx = static_cast<float>(opts_.boxMargin) * d.box.width, my = static_cast<float>(opts_.boxMargin) * d.box.height;
			boxes.push_back(cv::Rect2f(d.box.x - mx, d.box.y - my, d.box.width + 2 * mx, d.box.height + 2 * my) &
							cv::Rect2f(0, 0, static_cast<float>(image.width), static_cast<float>(image.height)));
		}
	if (boxes.empty()) return;
	for (std::size_t i = 0; i < f.keypoints.size(); i++)
	{
		if (f.dynamic[i]) continue;
		for (const auto& b : boxes)
			if (b.contains(f.keypoints[i].pt))
			{
				f.uncertain[i] = true;
				break;
			}
	}
}

TPoseEstimate CGeometricDynamicCheck::refine(
	const CPoseOptimizer& optimizer, const std::vector<TPoseObservation>& obs, const std::vector<bool>& uncertain,
	const mrpt::img::TCamera& K, const mrpt::poses::CPose3D& guess, TStats* stats) const
{
	TStats st;
	std::vector<std::size_t> certainIdx, uncertainIdx;
	for (std::size_t i = 0; i < obs.size(); i++) (i < uncertain.size() && uncertain[i] ? uncertainIdx : certainIdx).push_back(i);
	st.certain = certainIdx.size();
	st.uncertain = uncertainIdx.size();
	const auto plain = [&]
	{
		if (stats) *stats = st;
		return optimizer.refine(obs, K, guess);
	};
	if (!opts_.enabled || uncertainIdx.empty()) return plain();
	if (certainIdx.size() < opts_.minCertainInliers)
	{
		// Blinded: a dynamic object fills most of the view. A pose from what is left would mostly
		// come from the object (measured: 0.4-0.5 m off on office_loop), so there is none; tracking
		// reports the frame lost and keeps the prediction. With few features of either kind (a
		// textureless view) the check stands aside.
		if (uncertainIdx.size() >= certainIdx.size())
		{
			st.blinded = true;
			if (stats) *stats = st;
			TPoseEstimate none;
			none.inlier.assign(obs.size(), false);
			none.cameraInWorld = guess;
			return none;
		}
		return plain();
	}
	std::vector<TPoseObservation> certain;
	certain.reserve(certainIdx.size());
	for (std::size_t i : certainIdx) certain.push_back(obs[i]);
	const TPoseEstimate first = optimizer.refine(certain, K, guess);
	if (!first.ok || first.numInliers < opts_.minCertainInliers) return plain();

	std::vector<TPoseObservation> unsure;
	for (std::size_t i : uncertainIdx) unsure.push_back(obs[i]);
	const std::vector<bool> agree = optimizer.consistent(unsure, K, first.cameraInWorld);
	std::vector<std::size_t> used = certainIdx;
	for (std::size_t j = 0; j < uncertainIdx.size(); j++)
		if (agree[j]) used.push_back(uncertainIdx[j]);
	st.applied = true;
	st.uncertainAccepted = used.size() - certainIdx.size();
	if (stats) *stats = st;

	TPoseEstimate out;
	if (st.uncertainAccepted == 0)
	{
		out = first;
		out.inlier.assign(obs.size(), false);
		for (std::size_t k = 0; k < certainIdx.size(); k++) out.inlier[certainIdx[k]] = first.inlier[k];
		return out;
	}
	std::vector<TPoseObservation> all;
	all.reserve(used.size());
	for (std::size_t i : used) all.push_back(obs[i]);
	const TPoseEstimate second = optimizer.refine(all, K, first.cameraInWorld);
	out = second;
	out.inlier.assign(obs.size(), false);
	for (std::size_t k = 0; k < used.size(); k++) out.inlier[used[k]] = second.inlier[k];
	return out;
}
}  // namespace mrpt_yesslam
