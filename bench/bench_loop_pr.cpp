// Place recognition quality on a yesslam-sim loop sequence (issue 13 item 6; the paper's figure 13
// and table 6): runs yesslam sequentially over the sequence, then scores every pair of keyframes at
// least [LoopClosing] minLoopAge apart with
//   bow_all:    the BoW score over all keypoints, people included (ORB-SLAM2's),
//   bow_static: the BoW score over static keypoints only (our keyframe words),
//   s_loop:     S_Loop = alpha s_BoW + (1 - alpha) S_G (eq. 19-20) on static keypoints,
//   s_loop_norm: the same with s_BoW normalised by the keyframe's best covisible score ([LoopClosing] normaliseBow),
// and compares each ranking with the ground truth: a pair is a true loop when the two camera
// centres are within 0.3 m and their optical axes within 20 degrees. Prints, per score, the
// average precision, the recall at 100 % precision and the precision at 50 % recall; then the
// S_B / S_G table of eight keyframes spread over the sequence (the paper's table 6).
//
// usage: bench_loop_pr --input SIM_FOLDER [--config CFG]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/jobs/SlamJob.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;

namespace
{
struct TPair
{
	double bowAll, bowStatic, sLoop, sLoopNorm;
	bool positive;
};

void report(const char* name, std::vector<TPair> pairs, double TPair::*score, std::size_t positives)
{
	std::sort(pairs.begin(), pairs.end(), [&](const TPair& a, const TPair& b) { return a.*score > b.*score; });
	std::size_t tp = 0, fp = 0;
	double ap = 0, recallAtFull = 0, precisionAtHalf = 0;
	bool stillFull = true, half = false;
	for (const auto& p : pairs)
	{
		(p.positive ? tp : fp)++;
		const double precision = double(tp) / double(tp + fp), recall = positives ? double(tp) / double(positives) : 0;
		if (p.positive) ap += precision / double(std::max<std::size_t>(1, positives));
		if (fp) stillFull = false;
		if (stillFull) recallAtFull = recall;
		if (!half && recall >= 0.5)
		{
			half = true;
			precisionAtHalf = precision;
		}
	}
	std::printf("%-11s AP %.3f  recall@100%%precision %.3f  precision@50%%recall %.3f\n", name, ap, recallAtFull,
				precisionAtHalf);
}
}  // namespace

int main(int argc, char** argv)
{
	return runTool(
		"bench_loop_pr",
		[&]
		{
			std::string input, config;
			CommandLine cl("bench_loop_pr", "bench_loop_pr --input SIM_FOLDER [--config CFG]",
						   "Scores place recognition (BoW with people, BoW static, S_Loop) against ground truth on a "
						   "yesslam-sim loop sequence.",
						   {"bench_loop_pr --input bench_out/loop/office_tour_s31"});
			cl.text("input", "DIR", "a yesslam-sim folder", &input, true);
			cl.text("config", "CFG", "config file (INI or YAML)", &config);
			if (!cl.parse(argc, argv)) return 0;
			TYesSlamOptions o;
			if (!config.empty()) o.loadFromFile(config);
			o.detector.backend = "auto";
			o.system.parallel = false;
			resolveDetector(o.detector, input);
			const TTrajectory gt = readTumTrajectory(input + "/groundtruth.txt");
			std::map<long long, mrpt::poses::CPose3D> gtByStamp;
			for (const auto& p : gt) gtByStamp[std::llround(p.t * 1000)] = p.asPose();
			CYesSlamSystem sys(o);
			auto src = openInputSource(input, o.input);
			while (auto obs = src->next()) sys.processFrame(*obs);
			sys.waitForMapping();
			if (!sys.vocabulary()) throw InputError("", "no vocabulary");
			const CVocabulary& voc = *sys.vocabulary();
			const auto db = std::make_shared<CBowDatabase>(voc.numWords());
			// The paper's eq. 19 as written (s_loop) and with the BoW score normalised (s_loop_norm).
			auto raw = o.loop.detection;
			raw.normaliseBow = false;
			CLoopDetector det(raw, sys.map(), sys.vocabulary(), db, o.keyFrames.semantic, o.orb.scaleFactor,
							  o.tracking.maxDepth);

			std::vector<CKeyFrame> kfs;
			std::vector<TBowVector> all;
			for (const auto id : sys.map().keyFrameIds())
			{
				CKeyFrame k = sys.map().keyFrame(id);
				if (!k.bow || !gtByStamp.count(std::llround(k.timestamp * 1000))) continue;
				TBowVector v;
				voc.transform(k.features->descriptors, v);
				all.push_back(std::move(v));
				kfs.push_back(std::move(k));
			}
			std::vector<TPair> pairs;
			std::size_t positives = 0;
			for (std::size_t i = 0; i < kfs.size(); i++)
				for (std::size_t j = i + 1; j < kfs.size(); j++)
				{
					if (kfs[j].timestamp - kfs[i].timestamp < o.loop.detection.minLoopAge) continue;
					const auto a = gtByStamp.at(std::llround(kfs[i].timestamp * 1000)),
							   b = gtByStamp.at(std::llround(kfs[j].timestamp * 1000));
					const double dist =
						std::sqrt(std::pow(a.x() - b.x(), 2) + std::pow(a.y() - b.y(), 2) + std::pow(a.z() - b.z(), 2));
					const auto Ra = a.getRotationMatrix(), Rb = b.getRotationMatrix();
					const double cosAxes = Ra(0, 2) * Rb(0, 2) + Ra(1, 2) * Rb(1, 2) + Ra(2, 2) * Rb(2, 2);
					const bool positive = dist < 0.3 && cosAxes > std::cos(20 * M_PI / 180);
					positives += positive;
					const double sb = CVocabulary::score(kfs[i].bow->words, kfs[j].bow->words);
					const double ref = det.referenceScore(kfs[j]);
					const double alpha = det.alphaOf(kfs[j]);
					const double norm = ref > 0 ? std::min(1.0, sb / ref) : sb;
					pairs.push_back({CVocabulary::score(all[i], all[j]), sb, det.loopScore(kfs[j], kfs[i]),
									 alpha * norm + (1 - alpha) * det.semanticSimilarity(kfs[j], kfs[i]), positive});
				}
			std::printf("keyframes %zu, pairs %zu (>= %.0f s apart), true loops %zu\n", kfs.size(), pairs.size(),
						o.loop.detection.minLoopAge, positives);
			report("bow_all", pairs, &TPair::bowAll, positives);
			report("bow_static", pairs, &TPair::bowStatic, positives);
			report("s_loop", pairs, &TPair::sLoop, positives);
			report("s_loop_norm", pairs, &TPair::sLoopNorm, positives);

			// Table 6: eight keyframes spread over the sequence; above the diagonal S_B (BoW static),
			// below it S_G (semantic), 1 on it.
			if (kfs.size() >= 8)
			{
				std::printf("\nS_B (upper) / S_G (lower) of 8 keyframes (stamps relative to the first):\n        ");
				std::vector<std::size_t> pick;
				for (int k = 0; k < 8; k++) pick.push_back(k * (kfs.size() - 1) / 7);
				for (const auto p : pick) std::printf("%7.1fs", kfs[p].timestamp - kfs[0].timestamp);
				std::printf("\n");
				for (std::size_t r = 0; r < 8; r++)
				{
					std::printf("%7.1fs", kfs[pick[r]].timestamp - kfs[0].timestamp);
					for (std::size_t c = 0; c < 8; c++)
					{
						const auto &A = kfs[pick[r]], &B = kfs[pick[c]];
						const double v = r == c ? 1.0
												: (c > r ? CVocabulary::score(A.bow->words, B.bow->words)
														 : det.semanticSimilarity(A, B));
						std::printf(" %7.4f", v);
					}
					std::printf("\n");
				}
			}
			return 0;
		});
}
