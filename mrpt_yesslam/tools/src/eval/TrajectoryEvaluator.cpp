#include "mrpt_yesslam/eval/TrajectoryEvaluator.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>

#include "mrpt_yesslam/io/Association.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
TErrorStats TErrorStats::of(const std::vector<double>& v)
{
	TErrorStats s;
	s.n = v.size();
	if (v.empty()) return s;
	double sum = 0, sq = 0;
	s.min = v[0];
	s.max = v[0];
	for (double x : v)
	{
		sum += x;
		sq += x * x;
		s.min = std::min(s.min, x);
		s.max = std::max(s.max, x);
	}
	const double n = static_cast<double>(v.size());
	s.mean = sum / n;
	s.rmse = std::sqrt(sq / n);
	double var = 0;
	for (double x : v) var += (x - s.mean) * (x - s.mean);
	s.std = std::sqrt(var / n);
	std::vector<double> sorted(v);
	std::sort(sorted.begin(), sorted.end());
	const std::size_t m = sorted.size() / 2;
	s.median = (sorted.size() % 2 == 1) ? sorted[m] : 0.5 * (sorted[m - 1] + sorted[m]);
	return s;
}

TAteResult computeAte(const TTrajectory& gtIn, const TTrajectory& estIn, const TEvalOptions& opts,
					  const std::string& gtName, const std::string& estName)
{
	const TTrajectory gt = uniqueSortedByTime(gtIn), est = uniqueSortedByTime(estIn);
	if (gt.empty()) throw InputError(gtName, "contains no poses");
	if (est.empty()) throw InputError(estName, "contains no poses");
	std::vector<double> tg, te;
	for (const auto& p : gt) tg.push_back(p.t);
	for (const auto& p : est) te.push_back(p.t);
	const auto matches = associateTimestamps(tg, te, opts.offset, opts.maxDiff);
	if (matches.size() < 3)
	{
		char buf[256];
		std::snprintf(
			buf, sizeof(buf),
			"only %zu of %zu poses have a ground-truth stamp within %g s (need at least 3); estimate spans %.3f..%.3f, "
			"ground truth %.3f..%.3f",
			matches.size(), est.size(), opts.maxDiff, te.front(), te.back(), tg.front(), tg.back());
		throw InputError(estName, buf);
	}
	TAteResult r;
	std::vector<Eigen::Vector3d> model, data;
	for (const auto& [ig, ie] : matches)
	{
		data.emplace_back(gt[ig].tx, gt[ig].ty, gt[ig].tz);
		model.emplace_back(est[ie].tx, est[ie].ty, est[ie].tz);
		r.stamps.push_back(gt[ig].t);
	}
	// Without alignment (a run in a saved map's frame, measured against ground truth in that frame)
	// the estimate is compared as it is.
	if (opts.align) r.alignment = alignPositions(model, data, opts.sim3);
	for (std::size_t i = 0; i < model.size(); i++)
	{
		const Eigen::Vector3d aligned = r.alignment.scale * r.alignment.R * model[i] + r.alignment.t;
		r.errors.push_back((aligned - data[i]).norm());
		r.estAligned.push_back(aligned);
	}
	r.gt = std::move(data);
	r.stats = TErrorStats::of(r.errors);
	return r;
}

namespace
{
using Mat4 = Eigen::Matrix4d;

// evaluate_rpe.py's transform44(): quaternion (qx qy qz qw) normalised through sqrt(2/|q|^2).
Mat4 transform44(const TStampedPose& p)
{
	Eigen::Vector4d q(p.qx, p.qy, p.qz, p.qw);
	const double nq = q.dot(q);
	Mat4 T = Mat4::Identity();
	T(0, 3) = p.tx;
	T(1, 3) = p.ty;
	T(2, 3) = p.tz;
	if (nq < 4.0 * std::numeric_limits<double>::epsilon()) return T;
	q *= std::sqrt(2.0 / nq);
	const Eigen::Matrix4d o = q * q.transpose();
	T(0, 0) = 1.0 - o(1, 1) - o(2, 2);
	T(0, 1) = o(0, 1) - o(2, 3);
	T(0, 2) = o(0, 2) + o(1, 3);
	T(1, 0) = o(0, 1) + o(2, 3);
	T(1, 1) = 1.0 - o(0, 0) - o(2, 2);
	T(1, 2) = o(1, 2) - o(0, 3);
	T(2, 0) = o(0, 2) - o(1, 3);
	T(2, 1) = o(1, 2) + o(0, 3);
	T(2, 2) = 1.0 - o(0, 0) - o(1, 1);
	return T;
}

// ominus(a, b) = inv(a) * b for rigid transforms.
Mat4 ominus(const Mat4& a, const Mat4& b)
{
	return a.inverse() * b;
}

// evaluate_rpe.py's find_closest_index(): a binary search that returns the closest element among
// those it visits. That is not always the true nearest; we reproduce it as it is.
std::size_t findClosestIndex(const std::vector<double>& L, double t)
{
	std::size_t beginning = 0, end = L.size(), best = 0;
	double difference = std::abs(L[0] - t);
	while (beginning < end)
	{
		const std::size_t middle = (end + beginning) / 2;
		if (std::abs(L[middle] - t) < difference)
		{
			difference = std::abs(L[middle] - t);
			best = middle;
		}
		if (t == L[middle]) return middle;
		if (L[middle] > t)
			end = middle;
		else
			beginning = middle + 1;
	}
	return best;
}
}  // namespace

TRpeResult computeRpe(const TTrajectory& gtIn, const TTrajectory& estIn, const TEvalOptions& opts, double scale,
					  const std::string& estName)
{
	const TTrajectory gt = uniqueSortedByTime(gtIn), est = uniqueSortedByTime(estIn);
	if (gt.size() < 2 || est.size() < 2) throw InputError(estName, "RPE needs at least 2 poses in each trajectory");
	std::vector<double> sg, se;
	for (const auto& p : gt) sg.push_back(p.t);
	for (const auto& p : est) se.push_back(p.t);
	std::vector<Mat4> Tg, Te;
	for (const auto& p : gt) Tg.push_back(transform44(p));
	for (const auto& p : est) Te.push_back(transform44(p));

	// The tool's overlap check: distinct estimate stamps reachable through the nearest gt stamp.
	{
		std::vector<std::size_t> seen;
		for (double t : se)
		{
			const double tGt = sg[findClosestIndex(sg, t + opts.offset)];
			const std::size_t k = findClosestIndex(se, tGt - opts.offset);
			if (std::find(seen.begin(), seen.end(), k) == seen.end()) seen.push_back(k);
			if (seen.size() >= 2) break;
		}
		if (seen.size() < 2) throw InputError(estName, "too little overlap with the ground-truth timestamps for RPE");
	}

	std::vector<double> index(se.size());
	for (std::size_t i = 0; i < se.size(); i++) index[i] = opts.rpeDeltaInFrames ? static_cast<double>(i) : se[i];
	std::vector<std::pair<std::size_t, std::size_t>> pairs;
	for (std::size_t i = 0; i < se.size(); i++)
	{
		const std::size_t j = findClosestIndex(index, index[i] + opts.rpeDelta);
		if (j != se.size() - 1) pairs.emplace_back(i, j);  // the tool drops pairs ending on the last pose
	}
	std::vector<double> diffs;
	for (std::size_t i = 1; i < sg.size(); i++) diffs.push_back(sg[i] - sg[i - 1]);
	const double gtMaxDiff = 2.0 * TErrorStats::of(diffs).median;

	std::vector<double> et, er;
	for (const auto& [i, j] : pairs)
	{
		const std::size_t g0 = findClosestIndex(sg, se[i] + opts.offset);
		const std::size_t g1 = findClosestIndex(sg, se[j] + opts.offset);
		if (std::abs(sg[g0] - (se[i] + opts.offset)) > gtMaxDiff ||
			std::abs(sg[g1] - (se[j] + opts.offset)) > gtMaxDiff)
			continue;
		Mat4 relEst = ominus(Te[j], Te[i]);
		relEst.block<3, 1>(0, 3) *= scale;
		const Mat4 relGt = ominus(Tg[g1], Tg[g0]);
		const Mat4 E = ominus(relEst, relGt);
		et.push_back(E.block<3, 1>(0, 3).norm());
		const double c = std::min(1.0, std::max(-1.0, (E.block<3, 3>(0, 0).trace() - 1.0) / 2.0));
		er.push_back(std::acos(c) * 180.0 / M_PI);
	}
	if (et.size() < 2) throw InputError(estName, "fewer than 2 pose pairs match the ground truth for RPE");
	TRpeResult r;
	r.pairs = et.size();
	r.trans = TErrorStats::of(et);
	r.rotDeg = TErrorStats::of(er);
	return r;
}
}  // namespace mrpt_yesslam
