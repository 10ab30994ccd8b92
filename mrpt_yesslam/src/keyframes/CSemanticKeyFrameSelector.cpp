#include "mrpt_yesslam/keyframes/CSemanticKeyFrameSelector.h"

#include <mrpt/config/CConfigFileBase.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "mrpt_yesslam/geometry/Alignment.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
COptionTable CSemanticKeyFrameSelector::TOptions::table()
{
	COptionTable t("KeyFrames");
	t.integer("gridCols", gridCols, 1, 64, "semantic regions across the image (eq. 9: n = cols x rows)");
	t.integer("gridRows", gridRows, 1, 64, "semantic regions down the image");
	t.real("gamma", gamma, 0, 1, "eq. 10 weight of the Jaccard similarity J against eta");
	t.integer("interval", interval, 1, 1000, "N_I: frames per keyframe interval (Algorithm 1)");
	t.integer("shortInterval", shortInterval, 1, 1000,
			  "N_I after excessiveFrames consecutive frames with D >= maxMotion");
	t.integer("excessiveFrames", excessiveFrames, 1, 1000,
			  "consecutive frames of excessive motion that shorten the interval");
	t.real("minMotion", minMotion, 0, 100, "D_min (m + rad): frames moving less are not candidates");
	t.real("maxMotion", maxMotion, 0, 100, "D_max (m + rad): excessive motion");
	t.real("minStaticRatio", minStaticRatio, 0, 1, "frames with N_sp <= this x N_p are skipped");
	t.count("minInliers", minInliers, 0, 100000, "a candidate needs more tracked inliers than this");
	t.flag("etaAsWritten", etaAsWritten, "eq. 8 literally (max 0.5) instead of the Dice form");
	return t;
}

std::vector<std::set<int>> semanticRegionVectors(const std::vector<TDetection>& dets, cv::Size image, int cols,
												 int rows)
{
	std::vector<std::set<int>> v(static_cast<std::size_t>(std::max(1, cols) * std::max(1, rows)));
	if (image.width <= 0 || image.height <= 0) return v;
	const float cw = static_cast<float>(image.width) / cols, ch = static_cast<float>(image.height) / rows;
	for (const auto& d : dets)
		for (int r = 0; r < rows; r++)
			for (int c = 0; c < cols; c++)
			{
				const cv::Rect2f region(c * cw, r * ch, cw, ch);
				if ((region & d.box).area() > 0) v[static_cast<std::size_t>(r * cols + c)].insert(d.classId);
			}
	return v;
}

double jaccardSimilarity(const std::vector<std::set<int>>& a, const std::vector<std::set<int>>& b)
{
	const std::size_t n = std::min(a.size(), b.size());
	if (n == 0) return 1.0;
	double sum = 0;
	for (std::size_t i = 0; i < n; i++)
	{
		std::size_t inter = 0;
		for (int c : a[i]) inter += b[i].count(c);
		const std::size_t uni = a[i].size() + b[i].size() - inter;
		sum += uni == 0 ? 1.0 : static_cast<double>(inter) / static_cast<double>(uni);
	}
	return sum / static_cast<double>(n);
}

double areaSimilarity(const std::vector<TDetection>& cur, const std::vector<TDetection>& ref, bool asWritten)
{
	double aCur = 0, aRef = 0;
	for (const auto& d : cur) aCur += d.box.area();
	for (const auto& d : ref) aRef += d.box.area();
	if (aCur + aRef <= 0) return asWritten ? 0.5 : 1.0;  // no boxes in either frame: identical
	// Pair boxes of the same class greedily by overlap: the "corresponding target boxes".
	struct P
	{
		double inter;
		std::size_t i, j;
	};
	std::vector<P> pairs;
	for (std::size_t i = 0; i < cur.size(); i++)
		for (std::size_t j = 0; j < ref.size(); j++)
			if (cur[i].classId == ref[j].classId)
			{
				const double inter = (cur[i].box & ref[j].box).area();
				if (inter > 0) pairs.push_back({inter, i, j});
			}
	std::sort(pairs.begin(), pairs.end(), [](const P& x, const P& y) { return x.inter > y.inter; });
	std::vector<char> usedC(cur.size(), 0), usedR(ref.size(), 0);
	double au = 0;
	for (const auto& p : pairs)
	{
		if (usedC[p.i] || usedR[p.j]) continue;
		usedC[p.i] = usedR[p.j] = 1;
		au += p.inter;
	}
	return (asWritten ? 1.0 : 2.0) * au / (aCur + aRef);
}

double motionAmplitude(const Eigen::Matrix3d& R, const Eigen::Vector3d& t)
{
	const double c = std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0);
	const double angle = std::acos(c);  // in [0, pi]
	return t.norm() + std::min(2.0 * M_PI - angle, angle);
}

bool rigidMotionFromPoints(const std::vector<Eigen::Vector3d>& cur, const std::vector<Eigen::Vector3d>& ref,
						   Eigen::Matrix3d& R, Eigen::Vector3d& t)
{
	if (cur.size() != ref.size() || cur.size() < 3) return false;
	// Degenerate (collinear) point sets have no unique rotation.
	Eigen::Vector3d mean = Eigen::Vector3d::Zero();
	for (const auto& p : ref) mean += p;
	mean /= static_cast<double>(ref.size());
	Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
	for (const auto& p : ref) cov += (p - mean) * (p - mean).transpose();
	Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
	if (es.eigenvalues()(1) <= 1e-12 * std::max(1.0, es.eigenvalues()(2))) return false;
	// The same closed form the evaluator uses for ATE alignment (eq. 13-15).
	const TAlignment a = alignPositions(ref, cur, false);
	R = a.R;
	t = a.t;
	return true;
}

CSemanticKeyFrameSelector::CSemanticKeyFrameSelector(const TOptions& o) : opts_(o), intervalLen_(o.interval)
{
	if (o.gridCols < 1 || o.gridRows < 1) throw InputError("", "[KeyFrames] gridCols and gridRows must be >= 1");
	if (o.interval < 1 || o.shortInterval < 1)
		throw InputError("", "[KeyFrames] interval and shortInterval must be >= 1");
	if (!(o.gamma >= 0 && o.gamma <= 1)) throw InputError("", "[KeyFrames] gamma must be in [0,1]");
	if (!(o.minMotion < o.maxMotion)) throw InputError("", "[KeyFrames] minMotion must be below maxMotion");
}

std::optional<std::size_t> CSemanticKeyFrameSelector::referenceId() const
{
	if (!ref_) return std::nullopt;
	return ref_->frameId;
}

void CSemanticKeyFrameSelector::restart(const TKeyFrameInput& f)
{
	ref_ = f;
	cand_.reset();
	candSim_ = 2;
	inInterval_ = 0;
	intervalLen_ = currentInterval();
}

double CSemanticKeyFrameSelector::similarityToReference(const TKeyFrameInput& f) const
{
	if (!ref_) return 1.0;
	const double J =
		jaccardSimilarity(semanticRegionVectors(f.detections, f.imageSize, opts_.gridCols, opts_.gridRows),
						  semanticRegionVectors(ref_->detections, ref_->imageSize, opts_.gridCols, opts_.gridRows));
	const double eta = areaSimilarity(f.detections, ref_->detections, opts_.etaAsWritten);
	return globalSimilarity(J, eta, opts_.gamma);
}

std::optional<CSemanticKeyFrameSelector::TDecision> CSemanticKeyFrameSelector::addFrame(const TKeyFrameInput& f)
{
	const bool enoughStatic =
		static_cast<double>(f.numStatic) > opts_.minStaticRatio * static_cast<double>(f.numFeatures);
	if (!ref_)
	{
		// The first keyframe: the first frame good enough to track from.
		if (!enoughStatic || f.numInliers <= opts_.minInliers) return std::nullopt;
		ref_ = f;
		return TDecision{f.frameId, 1.0};
	}
	// Lines 2-10 of Algorithm 1: three consecutive frames of excessive motion shorten the interval;
	// a frame of normal motion restores it.
	if (f.motion >= opts_.maxMotion)
	{
		if (++excessive_ >= opts_.excessiveFrames)
		{
			shortMode_ = true;
			excessive_ = 0;
		}
	}
	else
	{
		excessive_ = 0;
		if (f.motion > opts_.minMotion) shortMode_ = false;
	}
	if (!enoughStatic) return std::nullopt;  // line 13: not inserted into the interval
	inInterval_++;
	if (f.motion > opts_.minMotion)
	{
		const double s = similarityToReference(f);
		if (s < candSim_)
		{
			candSim_ = s;
			cand_ = f;
		}
	}
	if (inInterval_ < intervalLen_) return std::nullopt;
	std::optional<TDecision> out;
	if (cand_)
	{
		ref_ = cand_;  // line 21, whatever its inliers
		if (cand_->numInliers > opts_.minInliers) out = TDecision{cand_->frameId, candSim_};
	}
	inInterval_ = 0;
	cand_.reset();
	candSim_ = 2;
	intervalLen_ = currentInterval();
	return out;
}
}  // namespace mrpt_yesslam
