// Issue 5 item 2: which descriptor matcher tracking should use, measured. For frame pairs (k, k+gap)
// of a yesslam-sim sequence, the static keypoints of frame k (true labels; depth known) are matched
// against those of frame k+gap by:
//   - brute force: exact nearest Hamming neighbour, Lowe's ratio test (OpenCV BFMatcher),
//   - FLANN LSH: the paper's choice, approximate neighbours by locality-sensitive hashing,
//   - projection: ours (COrbMatcher::searchByProjection), keypoint k back-projected with its depth
//     and projected with a constant-velocity pose prediction, compared within 15 px.
// A match is correct when the keypoint of frame k, moved with the true poses and its true depth,
// lands within 3 px (of the matched keypoint's pyramid level) of it. Reported: correct matches per pair, precision and
// time. usage: bench_matching SIM_FOLDER [GAP=1] [PAIRS=60]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <opencv2/features2d.hpp>
#include <opencv2/flann.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/data/TFrame.h"
#include "mrpt_yesslam/feature/COrbMatcher.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/io/Trajectory.h"

using namespace mrpt_yesslam;
using Clock = std::chrono::steady_clock;

namespace
{
struct TResult
{
	double correct = 0, wrong = 0, ms = 0;
	int pairs = 0;
};

// Frame with only static keypoints (true class labels) that have depth.
TFrame loadFrame(const mrpt::obs::CObservation3DRangeScan& obs, const cv::Mat& classes, const COrbExtractor& orb)
{
	TFrame f;
	f.timestamp = observationTime(obs);
	f.camera = obs.cameraParamsIntensity;
	const cv::Mat depth = depthInMetres(obs);
	const TFeatures all = orb.extract(obs.intensityImage.asCvMatRef(), depth);
	for (std::size_t i = 0; i < all.keypoints.size(); i++)
	{
		const cv::Point p(static_cast<int>(all.keypoints[i].pt.x), static_cast<int>(all.keypoints[i].pt.y));
		if (all.depth[i] <= 0 || classes.at<uint8_t>(p) == 1) continue;  // no depth, or on a person
		f.features.keypoints.push_back(all.keypoints[i]);
		f.features.descriptors.push_back(all.descriptors.row(static_cast<int>(i)));
		f.features.depth.push_back(all.depth[i]);
		f.features.dynamic.push_back(false);
	}
	f.mapPoints.assign(f.size(), -1);
	return f;
}

mrpt::poses::CPose3D poseAt(const TTrajectory& gt, double t)
{
	const TStampedPose* best = &gt.front();
	for (const auto& e : gt)
		if (std::abs(e.t - t) < std::abs(best->t - t)) best = &e;
	return best->asPose();
}
}  // namespace

int main(int argc, char** argv)
{
	if (argc < 2)
	{
		std::fprintf(stderr, "usage: bench_matching SIM_FOLDER [GAP=1] [PAIRS=60]\n");
		return 1;
	}
	const std::string dir = argv[1];
	const int gap = argc > 2 ? std::stoi(argv[2]) : 1;
	const int pairs = argc > 3 ? std::stoi(argv[3]) : 60;
	const TTrajectory gt = readTumTrajectory(dir + "/groundtruth.txt");
	CTumFolderSource src(dir);
	COrbExtractor orb;
	const int stride = std::max<int>(1, static_cast<int>(src.sizeHint()) / (pairs + 1));
	std::size_t index = 0;
	std::set<std::size_t> wanted;  // frame indices to load
	for (int p = 0; p < pairs; p++)
		for (int k : {p * stride, p * stride + gap, p * stride + 2 * gap}) wanted.insert(static_cast<std::size_t>(k));
	std::map<std::size_t, TFrame> loaded;
	while (auto obs = src.next())
	{
		if (wanted.count(index))
		{
			char name[64];
			std::snprintf(name, sizeof(name), "%.6f.png", observationTime(*obs));
			const cv::Mat classes = cv::imread(dir + "/labels/class/" + name, cv::IMREAD_UNCHANGED);
			if (classes.empty()) return std::fprintf(stderr, "%s: no labels/class/%s\n", dir.c_str(), name), 1;
			loaded[index] = loadFrame(*obs, classes, orb);
			loaded[index].pose = poseAt(gt, loaded[index].timestamp);
		}
		index++;
	}
	std::map<std::string, TResult> res;
	const COrbMatcher matcher(100, 0.9);
	for (int p = 0; p < pairs; p++)
	{
		const std::size_t k0 = static_cast<std::size_t>(p * stride), k1 = k0 + static_cast<std::size_t>(gap),
						  k2 = k1 + static_cast<std::size_t>(gap);
		if (!loaded.count(k2)) break;
		// Matching keypoints of frame k1 (as map points with their true positions) into frame k2; the
		// prediction extrapolates the true motion k0 -> k1, as the tracker's motion model does.
		const TFrame& a = loaded[k1];
		const TFrame& b = loaded[k2];
		TLocalMapPoints pts;
		for (std::size_t i = 0; i < a.size(); i++)
		{
			const cv::Point3d c = a.backProject(i);
			pts.ids.push_back(static_cast<TPointId>(i));
			pts.positions.push_back(a.pose.composePoint(mrpt::math::TPoint3D(c.x, c.y, c.z)));
		}
		pts.descriptors = a.features.descriptors;
		auto isCorrect = [&](std::size_t ia, std::size_t ib)
		{
			const mrpt::math::TPoint3D pc = b.pose.inverseComposePoint(pts.positions[ia]);
			if (pc.z <= 0) return false;
			const double u = b.camera.fx() * pc.x / pc.z + b.camera.cx(),
						 v = b.camera.fy() * pc.y / pc.z + b.camera.cy();
			const cv::Point2f& q = b.features.keypoints[ib].pt;
			const double tol = 3.0 * std::pow(1.2, b.features.keypoints[ib].octave);  // pixels of its pyramid level
			return (u - q.x) * (u - q.x) + (v - q.y) * (v - q.y) < tol * tol;
		};
		auto score = [&](const std::string& name, const std::vector<std::pair<std::size_t, std::size_t>>& m, double ms)
		{
			auto& r = res[name];
			for (const auto& [ia, ib] : m) (isCorrect(ia, ib) ? r.correct : r.wrong) += 1;
			r.ms += ms;
			r.pairs++;
		};
		auto ratioMatches = [&](const std::vector<std::vector<cv::DMatch>>& knn)
		{
			std::vector<std::pair<std::size_t, std::size_t>> m;
			std::map<int, std::pair<float, std::size_t>> bestForB;  // one match per keypoint of b
			for (const auto& k : knn)
				if (k.size() == 2 && k[0].distance < 0.8f * k[1].distance && k[0].distance <= 100)
				{
					auto it = bestForB.find(k[0].trainIdx);
					if (it == bestForB.end() || k[0].distance < it->second.first)
						bestForB[k[0].trainIdx] = {k[0].distance, static_cast<std::size_t>(k[0].queryIdx)};
				}
			for (const auto& [ib, v] : bestForB) m.emplace_back(v.second, static_cast<std::size_t>(ib));
			return m;
		};
		{
			auto t0 = Clock::now();
			cv::BFMatcher bf(cv::NORM_HAMMING);
			std::vector<std::vector<cv::DMatch>> knn;
			bf.knnMatch(a.features.descriptors, b.features.descriptors, knn, 2);
			const auto m = ratioMatches(knn);
			score("brute force + ratio", m, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
		}
		{
			auto t0 = Clock::now();
			cv::FlannBasedMatcher lsh(cv::makePtr<cv::flann::LshIndexParams>(12, 20, 2));
			std::vector<std::vector<cv::DMatch>> knn;
			lsh.knnMatch(a.features.descriptors, b.features.descriptors, knn, 2);
			const auto m = ratioMatches(knn);
			score("FLANN LSH + ratio", m, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
		}
		{
			auto t0 = Clock::now();
			const mrpt::poses::CPose3D motion = a.pose - loaded[k0].pose;  // a relative to k0
			const mrpt::poses::CPose3D guess = a.pose + motion;
			const auto tm = matcher.searchByProjection(b, guess, pts, 15.0);
			std::vector<std::pair<std::size_t, std::size_t>> m;
			for (const auto& x : tm) m.emplace_back(x.point, x.keypoint);
			score("projection (ours)", m, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
		}
	}
	std::printf("%s: %d pairs, frames %d apart, static keypoints with depth only\n", dir.c_str(),
				res.begin()->second.pairs, gap);
	std::printf("%-22s %16s %10s %10s\n", "matcher", "correct / pair", "precision", "ms / pair");
	for (const auto& [name, r] : res)
		std::printf("%-22s %16.1f %10.3f %10.2f\n", name.c_str(), r.correct / r.pairs,
					r.correct / std::max(1.0, r.correct + r.wrong), r.ms / r.pairs);
	return 0;
}
