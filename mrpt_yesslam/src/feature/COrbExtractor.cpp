#include "mrpt_yesslam/feature/COrbExtractor.h"

#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <opencv2/imgproc.hpp>

#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
COptionTable COrbExtractor::TOptions::table()
{
	COptionTable t("ORB");
	t.integer("numFeatures", numFeatures, 10, 100000, "keypoints per frame");
	t.integer("numLevels", numLevels, 1, 16, "pyramid levels");
	t.real("scaleFactor", scaleFactor, 1.001, 1.999,
		   "pyramid scale between levels (search windows and sigmas follow it)");
	t.integer("fastThreshold", fastThreshold, 1, 100,
			  "FAST threshold: low (ORB-SLAM's retry value) so weak texture still gives corners");
	t.integer("cellSize", cellSize, 8, 1024, "grid cell side in pixels of each pyramid level");
	t.flag("excludeMasked", excludeMasked,
		   "false: keypoints in the mask are detected and flagged dynamic (eq. 3); true: not detected there");
	return t;
}

namespace
{
// `total` split over `levels` pyramid levels as ORB-SLAM and OpenCV's ORB split it (a geometric
// series in 1/scale), the rounding left to the last level.
std::vector<int> levelShares(int total, double scale, int levels)
{
	const double f = 1.0 / scale;
	double per = total * (1 - f) / (1 - std::pow(f, levels));
	std::vector<int> out;
	int sum = 0;
	for (int l = 0; l < levels - 1; l++)
	{
		out.push_back(static_cast<int>(std::round(per)));
		sum += out.back();
		per *= f;
	}
	out.push_back(std::max(0, total - sum));
	return out;
}

// Where level `octave`'s pixel coordinates lie in the image, less those coordinates times the
// scale: the pyramid is resized about pixel centres, so level pixel x lies at (x + 0.5) s - 0.5.
float pixelCentreOffset(double scaleFactor, int octave)
{
	return 0.5f * (static_cast<float>(std::pow(scaleFactor, octave)) - 1.f);
}
}  // namespace

COrbExtractor::COrbExtractor(const TOptions& o) : opts_(o)
{
	if (o.numFeatures < 10) throw InputError("", "[ORB] numFeatures must be at least 10");
	if (o.numLevels < 1 || o.numLevels > 16) throw InputError("", "[ORB] numLevels must be 1..16");
	if (!(o.scaleFactor > 1.0 && o.scaleFactor < 2.0)) throw InputError("", "[ORB] scaleFactor must be in (1, 2)");
	if (o.cellSize < 8) throw InputError("", "[ORB] cellSize must be at least 8");
	if (o.fastThreshold < 1 || o.fastThreshold > 100) throw InputError("", "[ORB] fastThreshold must be 1..100");
	// Detect generously; the grid then keeps an even subset.
	// One level: it describes each level's keypoints on the level image detect() already made, where
	// OpenCV's multi-level compute() rebuilt the whole pyramid first (a third of its time, issue 41).
	describer_ = cv::ORB::create(o.numFeatures, static_cast<float>(o.scaleFactor), 1, 19, 0, 2, cv::ORB::FAST_SCORE, 31,
								 o.fastThreshold);
	// ORB-SLAM's quota per level: geometric in the scale, so each level gets features in proportion
	// to its area; the candidates before the grid are OpenCV's ORB split of four times the budget
	// (what orb_->detect kept when it detected, before our own detection replaced it).
	perLevel_ = levelShares(o.numFeatures, o.scaleFactor, o.numLevels);
	candidatesPerLevel_ = levelShares(o.numFeatures * 4, o.scaleFactor, o.numLevels);
	// Row half-widths of the orientation patch's disc (radius 15: the 31-pixel patch), as ORB
	// defines it: rounded from the circle up to 45 degrees, then the rows above mirrored from the
	// columns below so that the disc is symmetric under a quarter turn (a plain rounded circle
	// turned half the angles by a degree or more against OpenCV's, and the descriptors with them).
	const int r = kHalfPatch;
	discHalfWidth_.assign(static_cast<std::size_t>(r + 2), 0);
	const int below = static_cast<int>(std::floor(r * std::sqrt(2.0) / 2 + 1)),
			  above = static_cast<int>(std::ceil(r * std::sqrt(2.0) / 2));
	for (int v = 0; v <= below; v++)
		discHalfWidth_[static_cast<std::size_t>(v)] = static_cast<int>(std::lround(std::sqrt(double(r * r - v * v))));
	for (int v = r, u = 0; v >= above; v--, u++)
	{
		while (discHalfWidth_[static_cast<std::size_t>(u)] == discHalfWidth_[static_cast<std::size_t>(u + 1)]) u++;
		discHalfWidth_[static_cast<std::size_t>(v)] = u;
	}
}

namespace
{
// Corners very often sit on depth discontinuities (an object's silhouette against what is behind
// it), where the depth under the keypoint may belong to either side, and a corner found at a
// coarse pyramid level is not exactly where the pixel is. A 3D point from such a depth is wrong by
// up to the depth step, which pose estimation from nearby views cannot see and so absorbs as a
// bias. The depth is kept only when the 5x5 neighbourhood is one surface (within 3% + 1 cm);
// the keypoint stays, without depth (as ORB-SLAM2 keeps keypoints without a stereo match).
// A well-mixed number from a keypoint's pixel (splitmix64's finaliser): an order without a side.
std::uint64_t positionHash(const cv::Point2f& p)
{
	std::uint64_t z =
		(static_cast<std::uint64_t>(std::lround(p.x * 16)) << 32) ^ static_cast<std::uint64_t>(std::lround(p.y * 16));
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

bool depthIsSmoothAround(const cv::Mat& depth, int x, int y, float z)
{
	const float tol = 0.03f * z + 0.01f;
	for (int dy = -2; dy <= 2; dy++)
		for (int dx = -2; dx <= 2; dx++)
		{
			const int xx = x + dx, yy = y + dy;
			if (xx < 0 || yy < 0 || xx >= depth.cols || yy >= depth.rows) continue;
			const float w = depth.at<float>(yy, xx);
			if (!(w > 0) || std::abs(w - z) > tol) return false;
		}
	return true;
}
}  // namespace

std::vector<cv::KeyPoint> COrbExtractor::detect(const cv::Mat& grey, const cv::Mat& keepMask,
												std::vector<cv::Mat>& pyramid) const
{
	// What OpenCV's ORB detect did, without its two costs we do not need (issue 41: ORB was the
	// frame thread's largest stage): the orientation of all four thousand candidates (only the
	// kept thousand need one: extract() orients them) and a bordered pyramid. Same pyramid (each level
	// resized from the one above, INTER_LINEAR_EXACT, sizes rounded as OpenCV's), same FAST
	// (9/16 with non-maximum suppression, OpenCV's SIMD code), same 19-pixel level border and
	// per-level candidate count by FAST score, so the keypoints are those it found.
	constexpr int kBorder = 19;  // OpenCV ORB's edgeThreshold: the descriptor's patch fits
	std::vector<cv::KeyPoint> out;
	pyramid.clear();
	cv::Mat level = grey;
	for (int l = 0; l < opts_.numLevels; l++)
	{
		const double scale = std::pow(opts_.scaleFactor, l);
		if (l > 0)
		{
			const cv::Size sz(cvRound(grey.cols / scale), cvRound(grey.rows / scale));
			if (sz.width <= 2 * kBorder || sz.height <= 2 * kBorder) break;
			cv::Mat next;
			cv::resize(level, next, sz, 0, 0, cv::INTER_LINEAR_EXACT);
			level = next;
		}
		pyramid.push_back(level);
		std::vector<cv::KeyPoint> kps;
		cv::FAST(level, kps, opts_.fastThreshold, true, cv::FastFeatureDetector::TYPE_9_16);
		cv::KeyPointsFilter::runByImageBorder(kps, level.size(), kBorder);
		if (!keepMask.empty())
			kps.erase(std::remove_if(kps.begin(), kps.end(),
									 [&](const cv::KeyPoint& k)
									 {
										 // Where the corner is in the image (the pixel-centre correction extract()
										 // applies later), so that flagDynamic() would judge it the same way.
										 const float off = pixelCentreOffset(opts_.scaleFactor, l);
										 const int x = std::min(keepMask.cols - 1,
																cvRound(k.pt.x * static_cast<float>(scale) + off)),
												   y = std::min(keepMask.rows - 1,
																cvRound(k.pt.y * static_cast<float>(scale) + off));
										 return keepMask.at<uchar>(y, x) == 0;
									 }),
					  kps.end());
		cv::KeyPointsFilter::retainBest(kps, candidatesPerLevel_[static_cast<std::size_t>(l)]);
		for (auto& k : kps)
		{
			k.octave = l;
			k.size = static_cast<float>(31 * scale);
			k.pt *= static_cast<float>(scale);
		}
		out.insert(out.end(), kps.begin(), kps.end());
	}
	return out;
}

float COrbExtractor::orientation(const cv::Mat& level, cv::Point2f pt) const
{
	// Rublee et al.'s intensity centroid over the disc of the descriptor's patch, in degrees
	// (what ORB's descriptor is steered by).
	const int cx = cvRound(pt.x), cy = cvRound(pt.y);
	int m01 = 0, m10 = 0;  // at most 31 x 31 x 255 x 15: fits
	for (int v = -kHalfPatch; v <= kHalfPatch; v++)
	{
		const int w = discHalfWidth_[static_cast<std::size_t>(std::abs(v))];
		const uchar* row = level.ptr<uchar>(cy + v);
		int sum = 0, wsum = 0;
		for (int u = -w; u <= w; u++)
		{
			const int I = row[cx + u];
			sum += I;
			wsum += u * I;
		}
		m10 += wsum;
		m01 += v * sum;
	}
	return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
}

cv::Mat COrbExtractor::describe(const std::vector<cv::Mat>& pyramid, const std::vector<cv::KeyPoint>& keypoints) const
{
	// Level by level, in level pixels: what OpenCV's compute() does after its own pyramid (the level
	// bordered by reflection, blurred 7x7, sigma 2, then the steered BRIEF tests), so the
	// descriptors are the ones it gave to the bit (bench_orb's checksum over 100 Bonn and 100
	// simulated frames; our pyramid's sizes are OpenCV's for 640x480 at scale 1.2).
	cv::Mat out(static_cast<int>(keypoints.size()), 32, CV_8U);
	std::vector<std::vector<std::size_t>> ofLevel(pyramid.size());
	for (std::size_t i = 0; i < keypoints.size(); i++)
		ofLevel[static_cast<std::size_t>(keypoints[i].octave)].push_back(i);
	for (std::size_t l = 0; l < pyramid.size(); l++)
	{
		if (ofLevel[l].empty()) continue;
		const float inv = static_cast<float>(1.0 / std::pow(opts_.scaleFactor, static_cast<double>(l)));
		std::vector<cv::KeyPoint> kps;
		kps.reserve(ofLevel[l].size());
		for (std::size_t i : ofLevel[l])
		{
			cv::KeyPoint k = keypoints[i];
			k.pt = cv::Point2f(static_cast<float>(cvRound(k.pt.x * inv)), static_cast<float>(cvRound(k.pt.y * inv)));
			k.octave = 0;
			k.size = 31;
			kps.push_back(k);
		}
		cv::Mat d;
		describer_->compute(pyramid[l], kps, d);
		// compute() drops keypoints too close to the border; detect() kept none there.
		if (d.rows != static_cast<int>(ofLevel[l].size()))
			throw std::logic_error("COrbExtractor: a keypoint was not described");
		for (std::size_t j = 0; j < ofLevel[l].size(); j++)
			d.row(static_cast<int>(j)).copyTo(out.row(static_cast<int>(ofLevel[l][j])));
	}
	return out;
}

TFeatures COrbExtractor::extract(const cv::Mat& image, const cv::Mat& depth, const cv::Mat& mask) const
{
	TFeatures out;
	out.levels = opts_.numLevels;
	if (image.empty()) return out;
	cv::Mat grey;
	if (image.channels() == 3)
		cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
	else
		grey = image;
	cv::Mat detectMask;
	if (opts_.excludeMasked && !mask.empty()) cv::bitwise_not(mask, detectMask);
	std::vector<cv::Mat> pyramid;
	const std::vector<cv::KeyPoint> all = detect(grey, detectMask, pyramid);

	// Per level: bucket into cells, then take the strongest remaining corner of every cell in turn
	// until the level's quota is met.
	std::vector<cv::KeyPoint> kept;
	std::vector<std::vector<cv::KeyPoint>> byLevel(pyramid.size());
	for (const auto& k : all) byLevel[static_cast<std::size_t>(k.octave)].push_back(k);
	for (std::size_t level = 0; level < byLevel.size(); level++)
	{
		const auto& kps = byLevel[level];
		const double scale = std::pow(opts_.scaleFactor, static_cast<double>(level));
		const double cell = opts_.cellSize * scale;
		const int cols = std::max(1, static_cast<int>(std::ceil(grey.cols / cell))),
				  rows = std::max(1, static_cast<int>(std::ceil(grey.rows / cell)));
		// Cells in row-major order, the order the round-robin below visits them in.
		std::vector<std::vector<cv::KeyPoint>> cells(static_cast<std::size_t>(cols * rows));
		for (const auto& k : kps)
		{
			const int cx = std::min(cols - 1, static_cast<int>(k.pt.x / cell)),
					  cy = std::min(rows - 1, static_cast<int>(k.pt.y / cell));
			cells[static_cast<std::size_t>(cy * cols + cx)].push_back(k);
		}
		for (auto& v : cells)
			// FAST scores are small integers, so ties are common: broken by a hash of the position, the choice depends
			// neither on the order the detector listed its corners in nor on a side of the cell (by row, the top rows
			// of every cell won). Which tied corner is kept moves a run's ATE by chance, as OpenCV's own order did.
			std::sort(v.begin(), v.end(),
					  [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
						  return a.response != b.response ? a.response > b.response
														  : positionHash(a.pt) < positionHash(b.pt);
					  });
		const int quota = perLevel_[level];
		int taken = 0;
		for (std::size_t round = 0; taken < quota; round++)
		{
			bool any = false;
			for (const auto& v : cells)
				if (round < v.size() && taken < quota)
				{
					kept.push_back(v[round]);
					taken++;
					any = true;
				}
			if (!any) break;
		}
	}
	// Oriented only now: a quarter of the candidates is kept.
	for (auto& k : kept)
	{
		const float inv = static_cast<float>(1.0 / std::pow(opts_.scaleFactor, k.octave));
		k.angle = orientation(pyramid[static_cast<std::size_t>(k.octave)], k.pt * inv);
	}
	out.descriptors = describe(pyramid, kept);
	// OpenCV's ORB reports a level-L corner at x_L * s (s = scaleFactor^L), but the pyramid is made
	// by resizing about pixel centres, so level pixel x_L lies at (x_L + 0.5) s - 0.5 in the image:
	// every keypoint of level L sat 0.5 (s - 1) pixels up and to the left (1.3 px at level 7).
	// Matching the same level across frames hides that; back-projecting depth and matching across
	// levels does not (it cost millimetres of trajectory jitter on simulated data). Corrected after
	// compute(), which must see the coordinates OpenCV produced.
	for (auto& k : kept)
	{
		const float off = pixelCentreOffset(opts_.scaleFactor, k.octave);
		k.pt.x += off;
		k.pt.y += off;
	}
	out.keypoints = std::move(kept);
	out.depth.assign(out.keypoints.size(), 0.f);
	out.dynamic.assign(out.keypoints.size(), false);
	if (!depth.empty())
		for (std::size_t i = 0; i < out.keypoints.size(); i++)
			out.depth[i] = depthAt(depth, out.keypoints[i].pt.x, out.keypoints[i].pt.y);
	flagDynamic(out, mask);
	return out;
}

float COrbExtractor::depthAt(const cv::Mat& depth, double px, double py)
{
	const int x = static_cast<int>(std::lround(px)), y = static_cast<int>(std::lround(py));
	if (depth.empty() || x < 0 || y < 0 || x >= depth.cols || y >= depth.rows) return 0.f;
	const float z = depth.at<float>(y, x);
	if (!(std::isfinite(z) && z > 0 && depthIsSmoothAround(depth, x, y, z))) return 0.f;
	// A keypoint lies between pixels (any keypoint of a coarser pyramid level does), and on a floor or a wall seen at a
	// slant the depth changes by up to a centimetre a pixel: the nearest pixel's depth put points off their ray's
	// surface, even on exact simulated depth. The four pixels around it lie within the smooth 5x5 window: interpolated.
	const int x0 = static_cast<int>(std::floor(px)), y0 = static_cast<int>(std::floor(py));
	if (x0 < 0 || y0 < 0 || x0 + 1 >= depth.cols || y0 + 1 >= depth.rows) return z;
	const float ax = static_cast<float>(px - x0), ay = static_cast<float>(py - y0);
	const auto d = [&](int dx, int dy) { return depth.at<float>(y0 + dy, x0 + dx); };
	return (1 - ay) * ((1 - ax) * d(0, 0) + ax * d(1, 0)) + ay * ((1 - ax) * d(0, 1) + ax * d(1, 1));
}

void COrbExtractor::flagDynamic(TFeatures& f, const cv::Mat& mask)
{
	f.dynamic.assign(f.keypoints.size(), false);
	if (mask.empty()) return;
	for (std::size_t i = 0; i < f.keypoints.size(); i++)
	{
		const int x = static_cast<int>(std::lround(f.keypoints[i].pt.x)),
				  y = static_cast<int>(std::lround(f.keypoints[i].pt.y));
		if (x >= 0 && y >= 0 && x < mask.cols && y < mask.rows) f.dynamic[i] = mask.at<uchar>(y, x) != 0;
	}
}
}  // namespace mrpt_yesslam
