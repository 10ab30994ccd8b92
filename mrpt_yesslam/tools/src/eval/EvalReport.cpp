#include "mrpt_yesslam/eval/EvalReport.h"

#include <cstdio>
#include <utility>
#include <vector>

#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
TEvalReport evaluateTrajectories(const TTrajectory& gt, const TTrajectory& est, const TEvalOptions& opts,
								 const std::string& gtName, const std::string& estName)
{
	TEvalReport r;
	r.options = opts;
	r.gtPoses = uniqueSortedByTime(gt).size();
	r.estPoses = uniqueSortedByTime(est).size();
	r.ate = computeAte(gt, est, opts, gtName, estName);
	std::vector<double> se, sg, j;
	for (std::size_t i = 1; i < r.ate.gt.size(); i++)
	{
		const Eigen::Vector3d de = r.ate.estAligned[i] - r.ate.estAligned[i - 1], dg = r.ate.gt[i] - r.ate.gt[i - 1];
		se.push_back(de.norm());
		sg.push_back(dg.norm());
		j.push_back((de - dg).norm());
	}
	r.stepEst = TErrorStats::of(se);
	r.stepGt = TErrorStats::of(sg);
	r.jitter = TErrorStats::of(j);
	try
	{
		r.rpe = computeRpe(gt, est, opts, r.ate.alignment.scale, estName);
		r.hasRpe = true;
	}
	catch (const InputError& e)
	{
		r.rpeProblem = e.what();
	}
	return r;
}

namespace
{
// Ordered (key, value) list shared by both output forms; numbers with 6 decimals like the TUM tools
// print, but with more digits so 1e-5 comparisons are meaningful.
std::vector<std::pair<std::string, std::string>> keyValues(const TEvalReport& r)
{
	auto num = [](double v)
	{
		char b[64];
		std::snprintf(b, sizeof(b), "%.9f", v);
		return std::string(b);
	};
	std::vector<std::pair<std::string, std::string>> kv;
	kv.emplace_back("gt_poses", std::to_string(r.gtPoses));
	kv.emplace_back("est_poses", std::to_string(r.estPoses));
	kv.emplace_back("alignment", !r.options.align ? "none" : r.ate.alignment.sim3 ? "sim3" : "se3");
	kv.emplace_back("scale", num(r.ate.alignment.scale));
	kv.emplace_back("ate_pairs", std::to_string(r.ate.stats.n));
	kv.emplace_back("ate_rmse", num(r.ate.stats.rmse));
	kv.emplace_back("ate_mean", num(r.ate.stats.mean));
	kv.emplace_back("ate_median", num(r.ate.stats.median));
	kv.emplace_back("ate_std", num(r.ate.stats.std));
	kv.emplace_back("ate_min", num(r.ate.stats.min));
	kv.emplace_back("ate_max", num(r.ate.stats.max));
	kv.emplace_back("rpe_pairs", std::to_string(r.hasRpe ? r.rpe.pairs : 0));
	if (r.hasRpe)
	{
		kv.emplace_back("rpe_delta", num(r.options.rpeDelta));
		kv.emplace_back("rpe_unit", r.options.rpeDeltaInFrames ? "f" : "s");
		kv.emplace_back("rpe_trans_rmse", num(r.rpe.trans.rmse));
		kv.emplace_back("rpe_trans_mean", num(r.rpe.trans.mean));
		kv.emplace_back("rpe_trans_median", num(r.rpe.trans.median));
		kv.emplace_back("rpe_trans_max", num(r.rpe.trans.max));
		kv.emplace_back("rpe_rot_rmse_deg", num(r.rpe.rotDeg.rmse));
		kv.emplace_back("rpe_rot_mean_deg", num(r.rpe.rotDeg.mean));
		kv.emplace_back("rpe_rot_median_deg", num(r.rpe.rotDeg.median));
		kv.emplace_back("rpe_rot_max_deg", num(r.rpe.rotDeg.max));
	}
	kv.emplace_back("step_est_median", num(r.stepEst.median));
	kv.emplace_back("step_gt_median", num(r.stepGt.median));
	kv.emplace_back("jitter_median", num(r.jitter.median));
	kv.emplace_back("jitter_rmse", num(r.jitter.rmse));
	return kv;
}

bool isNumber(const std::string& s)
{
	if (s.empty()) return false;
	for (char c : s)
		if (!((c >= '0' && c <= '9') || c == '.' || c == '-' || c == 'e' || c == '+')) return false;
	return true;
}
}  // namespace

std::string formatEvalKeyValues(const TEvalReport& r)
{
	std::string out;
	for (const auto& [k, v] : keyValues(r)) out += k + ": " + v + "\n";
	return out;
}

std::string formatAteErrorsCsv(const TAteResult& ate)
{
	std::string out = "stamp,error,dx,dy,dz\n";
	char line[160];
	for (std::size_t i = 0; i < ate.errors.size(); i++)
	{
		const Eigen::Vector3d d = ate.estAligned[i] - ate.gt[i];
		std::snprintf(line, sizeof line, "%.6f,%.6f,%.6f,%.6f,%.6f\n", ate.stamps[i], ate.errors[i], d.x(), d.y(),
					  d.z());
		out += line;
	}
	return out;
}

std::string formatEvalJson(const TEvalReport& r)
{
	std::string out = "{\n";
	for (const auto& [k, v] : keyValues(r)) out += "  \"" + k + "\": " + (isNumber(v) ? v : "\"" + v + "\"") + ",\n";
	if (!r.hasRpe)
	{
		std::string p;
		for (char c : r.rpeProblem) p += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
		out += "  \"rpe_problem\": \"" + p + "\",\n";
	}
	char b[128];
	out += "  \"alignment_transform\": {\n    \"rotation\": [";
	for (int i = 0; i < 3; i++)
	{
		std::snprintf(b, sizeof(b), "%s[%.12f, %.12f, %.12f]", i ? ", " : "", r.ate.alignment.R(i, 0),
					  r.ate.alignment.R(i, 1), r.ate.alignment.R(i, 2));
		out += b;
	}
	std::snprintf(b, sizeof(b), "],\n    \"translation\": [%.12f, %.12f, %.12f],\n", r.ate.alignment.t.x(),
				  r.ate.alignment.t.y(), r.ate.alignment.t.z());
	out += b;
	std::snprintf(b, sizeof(b), "    \"scale\": %.12f,\n", r.ate.alignment.scale);
	out += b;
	out += std::string("    \"type\": \"") + (r.ate.alignment.sim3 ? "sim3" : "se3") + "\"\n  }\n}\n";
	return out;
}
}  // namespace mrpt_yesslam
