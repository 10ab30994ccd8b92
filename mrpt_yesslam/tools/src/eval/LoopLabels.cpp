#include "mrpt_yesslam/eval/LoopLabels.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>

#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/TextParsing.h"

namespace mrpt_yesslam
{
namespace
{
const char* const kHeader =
	"query,query_stamp,candidate,candidate_stamp,bow_score,loop_score,min_score,stage,matches,inliers";

const std::vector<std::string> kDetectionStages{"covisible", "young", "below_min_score", "not_group_best",
												"inconsistent"};
// The stages a candidate reaches only past detection (consistency passed).
const std::vector<std::string> kVerificationStages{"gone",       "few_matches", "ransac",  "pose_solve",
												   "projection", "accepted",    "dropped", "untried"};

bool reachedVerification(const std::string& stage)
{
	return std::count(kVerificationStages.begin(), kVerificationStages.end(), stage) > 0;
}

// A whole non-negative number (ids, counts).
bool parseCount(const std::string& s, std::size_t& out)
{
	if (s.empty() || s.size() > 18 || !std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; }))
		return false;
	out = static_cast<std::size_t>(std::stoull(s));
	return true;
}

// The ground-truth pose nearest in time to `t` within `maxDiff` (gt sorted by stamp).
const TStampedPose* nearest(const TTrajectory& gt, double t, double maxDiff)
{
	const auto it = std::lower_bound(gt.begin(), gt.end(), t, [](const TStampedPose& p, double s) { return p.t < s; });
	const TStampedPose* best = nullptr;
	if (it != gt.end()) best = &*it;
	if (it != gt.begin() && (!best || t - std::prev(it)->t < best->t - t)) best = &*std::prev(it);
	return best && std::abs(best->t - t) <= maxDiff ? best : nullptr;
}

// Whether the point `depth` m ahead of camera a lies in camera b's view.
bool seesCentreOf(const mrpt::poses::CPose3D& a, const mrpt::poses::CPose3D& b, const TLoopLabelOptions& o)
{
	double wx, wy, wz, x, y, z;
	a.composePoint(0, 0, o.viewDepth, wx, wy, wz);
	b.inverseComposePoint(wx, wy, wz, x, y, z);
	const double rad = M_PI / 180.0;
	return z > 0 && std::abs(std::atan2(x, z)) <= o.halfFovXDeg * rad &&
		   std::abs(std::atan2(y, z)) <= o.halfFovYDeg * rad;
}

std::string ratio(std::size_t n, std::size_t d)
{
	return d ? formatNumber(static_cast<double>(n) / static_cast<double>(d), 3) : "nan";
}
}  // namespace

std::vector<TLabelledLoopCandidate> readLoopCandidatesCsv(const std::string& path)
{
	const auto lines = splitLines(readTextFile(path));
	if (lines.empty() || lines[0] != kHeader)
		throw InputError(
			path, "not a loop_candidates.csv (yesslam writes one; its first line is '" + std::string(kHeader) + "')");
	std::vector<TLabelledLoopCandidate> rows;
	for (std::size_t n = 1; n < lines.size(); n++)
	{
		if (lines[n].empty()) continue;
		const auto f = splitFields(lines[n]);
		const std::string where = "line " + std::to_string(n + 1) + ": ";
		if (f.size() != 10)
			throw InputError(
				path, where + "expected 10 fields (" + std::string(kHeader) + "), got " + std::to_string(f.size()));
		TLabelledLoopCandidate r;
		if (!parseCount(f[0], r.query)) throw InputError(path, where + "query '" + f[0] + "' is not a keyframe id");
		if (!parseCount(f[2], r.candidate))
			throw InputError(path, where + "candidate '" + f[2] + "' is not a keyframe id");
		if (!parseCount(f[8], r.matches) || !parseCount(f[9], r.inliers))
			throw InputError(path, where + "matches and inliers must be whole numbers");
		double* const numbers[] = {&r.queryStamp, &r.candidateStamp, &r.bowScore, &r.loopScore, &r.minScore};
		const std::size_t at[] = {1, 3, 4, 5, 6};
		for (int k = 0; k < 5; k++)
			if (!parseFiniteDouble(f[at[k]], *numbers[k]))
				throw InputError(path, where + "'" + f[at[k]] + "' is not a finite number");
		r.stage = f[7];
		if (!reachedVerification(r.stage) && !std::count(kDetectionStages.begin(), kDetectionStages.end(), r.stage))
			throw InputError(path, where + "unknown stage '" + r.stage + "'");
		rows.push_back(r);
	}
	return rows;
}

TLoopLabelReport labelLoopCandidates(std::vector<TLabelledLoopCandidate> rows, const TTrajectory& gtIn,
									 const TLoopLabelOptions& o)
{
	TTrajectory gt = gtIn;
	std::sort(gt.begin(), gt.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
	TLoopLabelReport rep;
	for (auto& r : rows)
	{
		const TStampedPose *a = nearest(gt, r.queryStamp, o.maxDiff), *b = nearest(gt, r.candidateStamp, o.maxDiff);
		if (!a || !b)
		{
			rep.unlabelled++;
			continue;
		}
		const mrpt::poses::CPose3D pa = a->asPose(), pb = b->asPose();
		r.labelled = true;
		r.distance = std::hypot(pa.x() - pb.x(), pa.y() - pb.y(), pa.z() - pb.z());
		// Viewing directions: the cameras' z axes (a roll about the axis keeps the view).
		const auto Ra = pa.getRotationMatrix(), Rb = pb.getRotationMatrix();
		const Eigen::Vector3d za(Ra(0, 2), Ra(1, 2), Ra(2, 2)), zb(Rb(0, 2), Rb(1, 2), Rb(2, 2));
		r.angleDeg = std::atan2(za.cross(zb).norm(), za.dot(zb)) * 180.0 / M_PI;  // exact near 0, unlike acos
		r.trueRevisit = r.distance <= o.maxDistance && r.angleDeg <= o.maxAngleDeg && seesCentreOf(pa, pb, o) &&
						seesCentreOf(pb, pa, o);
		auto& [t, f] = rep.byStage[r.stage];
		(r.trueRevisit ? t : f)++;
		const bool detected = reachedVerification(r.stage), accepted = r.stage == "accepted";
		rep.trueCandidates += r.trueRevisit;
		rep.trueLoopCandidates += r.trueRevisit && r.stage != "covisible" && r.stage != "young";
		rep.detected += detected;
		rep.trueDetected += detected && r.trueRevisit;
		rep.trueTried += detected && r.trueRevisit && r.stage != "untried";
		rep.accepted += accepted;
		rep.trueAccepted += accepted && r.trueRevisit;
	}
	rep.rows = std::move(rows);
	return rep;
}

std::string formatLoopLabelReport(const TLoopLabelReport& r)
{
	std::string out;
	out += "loop_candidates: " + std::to_string(r.rows.size() - r.unlabelled) + "\n";
	out += "loop_unlabelled: " + std::to_string(r.unlabelled) + "\n";
	out += "loop_true_candidates: " + std::to_string(r.trueCandidates) + "\n";
	out += "loop_true_not_covisible: " + std::to_string(r.trueLoopCandidates) + "\n";
	out += "loop_detected: " + std::to_string(r.detected) + "\n";
	out += "loop_detected_true: " + std::to_string(r.trueDetected) + "\n";
	out += "loop_accepted: " + std::to_string(r.accepted) + "\n";
	out += "loop_accepted_true: " + std::to_string(r.trueAccepted) + "\n";
	out += "detection_precision: " + ratio(r.trueDetected, r.detected) + "\n";
	out += "detection_recall: " + ratio(r.trueDetected, r.trueLoopCandidates) + "\n";
	out += "verification_precision: " + ratio(r.trueAccepted, r.accepted) + "\n";
	out += "verification_recall: " + ratio(r.trueAccepted, r.trueTried) + "\n";
	for (const auto& [stage, tf] : r.byStage)
		out += "stage_" + stage + ": " + std::to_string(tf.first) + " true, " + std::to_string(tf.second) + " false\n";
	return out;
}

std::string formatLabelledLoopCandidatesCsv(const TLoopLabelReport& r)
{
	std::string out = std::string(kHeader) + ",true_revisit,distance_m,angle_deg\n";
	char buf[320];
	for (const auto& c : r.rows)
	{
		std::snprintf(buf, sizeof(buf), "%zu,%.6f,%zu,%.6f,%.5f,%.5f,%.5f,%s,%zu,%zu,%s,%.4f,%.2f\n", c.query,
					  c.queryStamp, c.candidate, c.candidateStamp, c.bowScore, c.loopScore, c.minScore, c.stage.c_str(),
					  c.matches, c.inliers, c.labelled ? (c.trueRevisit ? "1" : "0") : "", c.distance, c.angleDeg);
		out += buf;
	}
	return out;
}
}  // namespace mrpt_yesslam
