#include "mrpt_yesslam/dynamic/CDynamicObjectMasker.h"

#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
COptionTable CDynamicObjectMasker::TOptions::table()
{
	COptionTable t("DynamicMask");
	t.text("method", method,
		   "edge_fill: the paper's Laplacian-enhanced fill; fill: plain depth flood fill; box: the whole box",
		   {"edge_fill", "fill", "box"});
	t.real("loDiff", loDiff, 0, 10,
		   "fill tolerance towards the camera between neighbours, m (the paper's 5 grey levels: about 0.13)");
	t.real("upDiff", upDiff, 0, 10, "fill tolerance away from the camera between neighbours, m");
	t.text("fillCompare", fillCompare,
		   "neighbour: each pixel against its filled neighbour (floating range, capped by maxDepthRange); seed: "
		   "against the seed (eq. 2 as written, fixed range)",
		   {"neighbour", "seed"});
	t.real("laplacianGain", laplacianGain, 0, 100, "k in f - k * lap(f) (eq. 4)");
	t.integer("laplacianKernel", laplacianKernel, 1, 7, "aperture of the Laplacian (1, 3, 5, 7)");
	t.real("blurSigma", blurSigma, 0, 100, "sigma of the Gaussian blur (eq. 5), pixels at the fill resolution");
	t.real("boxMargin", boxMargin, 0, 1, "the fill may leave the box by this share of its size");
	t.real("maxFillRatio", maxFillRatio, 0, 1, "a fill covering more of the box than this leaked: use the box");
	t.real("minFillRatio", minFillRatio, 0, 1, "a fill covering less of the box than this failed: use the box");
	t.flag("fallbackToBox", fallbackToBox, "on a failed fill mask the whole box (false: mask nothing)");
	t.integer("dilatePixels", dilatePixels, 0, 100,
			  "grow each object's mask by about this many full-resolution pixels");
	t.real("maxDepth", maxDepth, 0.1, 100, "depth beyond this is treated as missing, m");
	t.real("maxDepthRange", maxDepthRange, 0, 100,
		   "the fill never takes depth farther than this from the seed's, m (0 = no limit)");
	t.integer("downsample", downsample, 1, 4, "fill at 1/downsample of the image side (1 = full resolution)");
	t.integer("holdFrames", holdFrames, 0, 300,
			  "a missed dynamic object stays masked this many frames after its last detection (0 = off)");
	t.real("holdGrow", holdGrow, 0, 1, "each frame a held box grows by this share of its size on every side");
	return t;
}

CDynamicObjectMasker::CDynamicObjectMasker(const TOptions& o) : opts_(o)
{
	if (o.method != "edge_fill" && o.method != "fill" && o.method != "box")
		throw InputError("", "[DynamicMask] method must be edge_fill, fill or box, got '" + o.method + "'");
	if (!(o.loDiff >= 0) || !(o.upDiff >= 0)) throw InputError("", "[DynamicMask] loDiff and upDiff must be >= 0");
	if (o.fillCompare != "neighbour" && o.fillCompare != "seed")
		throw InputError("", "[DynamicMask] fillCompare must be neighbour or seed, got '" + o.fillCompare + "'");
	if (o.laplacianKernel != 1 && o.laplacianKernel != 3 && o.laplacianKernel != 5 && o.laplacianKernel != 7)
		throw InputError("", "[DynamicMask] laplacianKernel must be 1, 3, 5 or 7");
	if (o.downsample < 1 || o.downsample > 4) throw InputError("", "[DynamicMask] downsample must be 1..4");
	if (!(o.maxFillRatio > o.minFillRatio)) throw InputError("", "[DynamicMask] maxFillRatio must exceed minFillRatio");
	if (o.holdFrames < 0 || o.holdFrames > 300) throw InputError("", "[DynamicMask] holdFrames must be 0..300");
	if (!(o.holdGrow >= 0 && o.holdGrow <= 1)) throw InputError("", "[DynamicMask] holdGrow must be in [0, 1]");
}

cv::Mat CDynamicObjectMasker::prepare(const cv::Mat& depth) const
{
	cv::Mat d;
	depth.convertTo(d, CV_32F);
	cv::patchNaNs(d, 0.0);
	const cv::Mat invalid = (d <= 0) | (d > opts_.maxDepth);
	d.setTo(0, invalid);
	if (opts_.method == "edge_fill")
	{
		// Eq. 4-5: Laplacian sharpening steepens depth discontinuities, the blur removes the noise the
		// Laplacian amplified. Missing pixels are barriers again afterwards.
		// The filters see missing depth as its nearest valid neighbour's, not as 0: a hole (a dark
		// patch, a depth-edge dropout) read as 0 m is a step of the full depth, which the Laplacian
		// multiplies and the blur spreads into the surface round it, so a fill stopped at every hole
		// of a person (as eq. 4 is written for an image without holes).
		cv::Mat src = d;
		const int missing = cv::countNonZero(invalid);
		if (missing > 0 && missing < invalid.rows * invalid.cols)
		{
			cv::Mat dist, labels;
			cv::distanceTransform(invalid, dist, labels, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
			std::vector<float> value(static_cast<std::size_t>(d.rows) * static_cast<std::size_t>(d.cols) + 1, 0.0f);
			for (int y = 0; y < d.rows; y++)
			{
				const uchar* pi = invalid.ptr<uchar>(y);
				const int* pl = labels.ptr<int>(y);
				const float* pd = d.ptr<float>(y);
				for (int x = 0; x < d.cols; x++)
					if (!pi[x]) value[static_cast<std::size_t>(pl[x])] = pd[x];
			}
			src = d.clone();
			for (int y = 0; y < d.rows; y++)
			{
				const uchar* pi = invalid.ptr<uchar>(y);
				const int* pl = labels.ptr<int>(y);
				float* ps = src.ptr<float>(y);
				for (int x = 0; x < d.cols; x++)
					if (pi[x]) ps[x] = value[static_cast<std::size_t>(pl[x])];
			}
		}
		cv::Mat lap;
		cv::Laplacian(src, lap, CV_32F, opts_.laplacianKernel);
		cv::Mat enhanced = src - opts_.laplacianGain * lap;
		if (opts_.blurSigma > 0) cv::GaussianBlur(enhanced, enhanced, cv::Size(0, 0), opts_.blurSigma);
		enhanced.setTo(0, invalid);
		return enhanced;
	}
	return d;
}

bool CDynamicObjectMasker::fillBox(const cv::Mat& raw, const cv::Rect& box, cv::Mat& out, cv::Rect& outRoi,
								   cv::Point& seed) const
{
	// The fill may leave the box by a margin, never more.
	const int mx = static_cast<int>(std::round(box.width * opts_.boxMargin));
	const int my = static_cast<int>(std::round(box.height * opts_.boxMargin));
	const cv::Rect full(0, 0, raw.cols, raw.rows);
	const cv::Rect roi = cv::Rect(box.x - mx, box.y - my, box.width + 2 * mx, box.height + 2 * my) & full;
	// Filter only around the box (with room for the kernels): most of the time of a full-frame filter
	// would be spent on pixels no fill can reach.
	const int pad = opts_.laplacianKernel + static_cast<int>(std::ceil(4 * opts_.blurSigma)) + 1;
	const cv::Rect padded = cv::Rect(roi.x - pad, roi.y - pad, roi.width + 2 * pad, roi.height + 2 * pad) & full;
	const cv::Mat prepared = prepare(raw(padded));
	// `img` is addressed in frame coordinates but only valid on `padded`.
	const cv::Point off = padded.tl();
	auto imgAt = [&](int y, int x) { return prepared.at<float>(y - off.y, x - off.x); };
	const cv::Mat sub = prepared(roi - off);

	// Seed: dominant (preferably nearest) depth mode of the box's central part, pixel nearest the centre.
	const cv::Rect centre(box.x + box.width * 3 / 10, box.y + box.height / 5, std::max(1, box.width * 2 / 5),
						  std::max(1, box.height * 2 / 5));
	const cv::Rect c = centre & roi;
	const double binW = 0.05;
	std::vector<int> hist(static_cast<std::size_t>(opts_.maxDepth / binW) + 2, 0);
	int valid = 0;
	for (int y = c.y; y < c.y + c.height; y++)
		for (int x = c.x; x < c.x + c.width; x++)
		{
			const float v = imgAt(y, x);
			if (v <= 0) continue;
			hist[std::min(hist.size() - 1, static_cast<std::size_t>(v / binW))]++;
			valid++;
		}
	if (valid == 0) return false;
	std::vector<int> smooth(hist.size(), 0);
	for (std::size_t i = 0; i < hist.size(); i++)
		smooth[i] = hist[i] + (i > 0 ? hist[i - 1] : 0) + (i + 1 < hist.size() ? hist[i + 1] : 0);
	const std::size_t peak = static_cast<std::size_t>(std::max_element(smooth.begin(), smooth.end()) - smooth.begin());
	std::size_t mode = peak;
	for (std::size_t i = 0; i < peak; i++)
		if (smooth[i] >= smooth[peak] / 2 && (i == 0 || smooth[i] >= smooth[i - 1]) && smooth[i] >= smooth[i + 1])
		{
			mode = i;  // a nearer mode almost as strong: the object in front
			break;
		}
	const double modeDepth = (mode + 0.5) * binW;
	const cv::Point2f mid(box.x + box.width / 2.0f, box.y + box.height / 2.0f);
	double bestD = 1e18;
	seed = {-1, -1};
	for (int y = c.y; y < c.y + c.height; y++)
		for (int x = c.x; x < c.x + c.width; x++)
		{
			const float v = imgAt(y, x);
			if (v <= 0 || std::abs(v - modeDepth) > 1.5 * binW) continue;
			const double dd = (x - mid.x) * (x - mid.x) + (y - mid.y) * (y - mid.y);
			if (dd < bestD)
			{
				bestD = dd;
				seed = {x, y};
			}
		}
	if (seed.x < 0) return false;

	// 4-neighbour floating-range fill, mask only; missing depth is pre-marked as a barrier.
	cv::Mat fm = cv::Mat::zeros(roi.height + 2, roi.width + 2, CV_8U);
	fm(cv::Rect(1, 1, roi.width, roi.height)).setTo(1, sub <= 0);
	if (opts_.maxDepthRange > 0)
	{
		// A person is less than a metre deep: never follow a surface (floor, desk) farther than this
		// from the seed's depth. Tested on the raw depth, which sharpening has not moved.
		const float z0 = raw.at<float>(seed);
		const cv::Mat rs = raw(roi);
		fm(cv::Rect(1, 1, roi.width, roi.height))
			.setTo(1, (rs < z0 - opts_.maxDepthRange) | (rs > z0 + opts_.maxDepthRange));
	}
	// Eq. 2 compares every pixel with the seed (OpenCV's fixed range); comparing with the filled
	// neighbour instead follows a body that bends away from the camera (our default, with the
	// maxDepthRange cap above against runs along the floor).
	const int range = opts_.fillCompare == "seed" ? cv::FLOODFILL_FIXED_RANGE : 0;
	cv::floodFill(sub, fm, seed - roi.tl(), cv::Scalar(), nullptr, cv::Scalar(opts_.loDiff), cv::Scalar(opts_.upDiff),
				  4 | cv::FLOODFILL_MASK_ONLY | range | (255 << 8));
	cv::Mat filled = fm(cv::Rect(1, 1, roi.width, roi.height)) == 255;
	// Sharpening and blur make the object's own outermost pixels differ from their neighbours, so the
	// fill stops a pixel or two short of the silhouette. Grow it back, one 4-neighbour layer at a
	// time, where the raw depth is continuous with a filled neighbour (a conditional dilation on the
	// unfiltered depth). Only the frontier is visited: a whole-image morphological version cost half
	// of the masker's time.
	if (opts_.method == "edge_fill")
	{
		const cv::Mat rawSub = raw(roi);
		const int steps = 1 + static_cast<int>(std::ceil(2 * opts_.blurSigma));
		const float lo = static_cast<float>(opts_.loDiff), up = static_cast<float>(opts_.upDiff);
		std::vector<cv::Point> frontier, next;
		for (int y = 0; y < filled.rows; y++)
		{
			const uchar* row = filled.ptr<uchar>(y);
			for (int x = 0; x < filled.cols; x++)
				if (row[x] &&
					((x > 0 && !row[x - 1]) || (x + 1 < filled.cols && !row[x + 1]) ||
					 (y > 0 && !filled.at<uchar>(y - 1, x)) || (y + 1 < filled.rows && !filled.at<uchar>(y + 1, x))))
					frontier.emplace_back(x, y);
		}
		static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
		for (int it = 0; it < steps && !frontier.empty(); it++)
		{
			next.clear();
			for (const auto& p : frontier)
			{
				const float zp = rawSub.at<float>(p);
				for (int k = 0; k < 4; k++)
				{
					const int x = p.x + dx[k], y = p.y + dy[k];
					if (x < 0 || y < 0 || x >= filled.cols || y >= filled.rows) continue;
					uchar& m = filled.at<uchar>(y, x);
					if (m) continue;
					const float z = rawSub.at<float>(y, x);
					if (z > 0 && z >= zp - lo && z <= zp + up)
					{
						m = 255;
						next.emplace_back(x, y);
					}
				}
			}
			frontier.swap(next);
		}
	}
	// Close small gaps and add holes the object encloses (missing depth inside a person).
	cv::morphologyEx(filled, filled, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));
	std::vector<std::vector<cv::Point>> contours;
	cv::findContours(filled.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
	cv::drawContours(filled, contours, -1, cv::Scalar(255), cv::FILLED);
	const double ratio = cv::countNonZero(filled((box - roi.tl()) & cv::Rect(0, 0, roi.width, roi.height))) /
						 std::max(1.0, static_cast<double>(box.area()));
	if (ratio > opts_.maxFillRatio || ratio < opts_.minFillRatio) return false;
	out = filled;
	outRoi = roi;
	return true;
}

std::vector<TDetection> CDynamicObjectMasker::withHeld(const std::vector<TDetection>& dets, std::vector<bool>& held)
{
	std::vector<TDetection> all = dets;
	held.assign(dets.size(), false);
	if (opts_.holdFrames <= 0) return all;
	std::vector<THeld> next;
	for (const auto& h : held_)
	{
		// Seen again (the same class overlapping its last box): the new detection replaces it.
		const bool seen =
			std::any_of(dets.begin(), dets.end(),
						[&](const TDetection& d)
						{ return d.dynamic && d.classId == h.det.classId && boxIoU(d.box, h.det.box) >= 0.3; });
		if (seen || h.age >= opts_.holdFrames) continue;
		TDetection g = h.det;
		const float k = static_cast<float>(opts_.holdGrow * (h.age + 1));
		g.box = cv::Rect2f(g.box.x - k * g.box.width, g.box.y - k * g.box.height, g.box.width * (1 + 2 * k),
						   g.box.height * (1 + 2 * k));
		all.push_back(g);
		held.push_back(true);
		next.push_back({h.det, h.age + 1});
	}
	for (const auto& d : dets)
		if (d.dynamic) next.push_back({d, 0});
	held_ = std::move(next);
	return all;
}

TDynamicMask CDynamicObjectMasker::compute(const cv::Mat& depth, const std::vector<TDetection>& given)
{
	std::vector<bool> held;
	const std::vector<TDetection> dets = withHeld(given, held);
	return segment(depth, dets, held, true);
}

TDynamicMask CDynamicObjectMasker::segmentAll(const cv::Mat& depth, const std::vector<TDetection>& dets) const
{
	return segment(depth, dets, std::vector<bool>(dets.size(), false), false);
}

TDynamicMask CDynamicObjectMasker::segment(const cv::Mat& depth, const std::vector<TDetection>& dets,
										   const std::vector<bool>& held, bool onlyDynamic) const
{
	TDynamicMask r;
	r.mask = cv::Mat::zeros(depth.size(), CV_8U);
	r.classLabels = cv::Mat::zeros(depth.size(), CV_16U);
	r.instanceLabels = cv::Mat::zeros(depth.size(), CV_16U);
	const cv::Rect image(0, 0, depth.cols, depth.rows);
	bool any = false;
	for (const auto& d : dets) any |= d.dynamic || !onlyDynamic;
	if (!any || depth.empty()) return r;
	// Fills run on a depth image reduced by `downsample` (nearest neighbour, so no depth is mixed
	// across an edge); masks are scaled back up. Halving the side makes the masker 3-4 times faster
	// for a boundary error of about one full-resolution pixel, which the final dilation covers.
	const int f = opts_.method == "box" ? 1 : opts_.downsample;
	// Only the neighbourhood of each box is converted: full-frame conversions would cost more than
	// the fills themselves.
	cv::Mat raw;
	if (opts_.method != "box")
	{
		raw = cv::Mat::zeros(depth.rows / f, depth.cols / f, CV_32F);
		const cv::Rect small(0, 0, raw.cols, raw.rows);
		const int pad = opts_.laplacianKernel + static_cast<int>(std::ceil(4 * opts_.blurSigma)) + 2;
		for (const auto& d : dets)
		{
			if (onlyDynamic && !d.dynamic) continue;
			const double mx = d.box.width * opts_.boxMargin / f + pad, my = d.box.height * opts_.boxMargin / f + pad;
			const cv::Rect s = cv::Rect(cv::Point(static_cast<int>(std::floor(d.box.x / f - mx)),
												  static_cast<int>(std::floor(d.box.y / f - my))),
										cv::Point(static_cast<int>(std::ceil(d.box.br().x / f + mx)),
												  static_cast<int>(std::ceil(d.box.br().y / f + my)))) &
							   small;
			if (s.area() <= 0) continue;
			const cv::Rect full = cv::Rect(s.x * f, s.y * f, s.width * f, s.height * f) & image;
			cv::Mat part;
			depth(full).convertTo(part, CV_32F);
			cv::patchNaNs(part, 0.0);
			part.setTo(0, (part <= 0) | (part > opts_.maxDepth));
			if (f > 1)
				cv::resize(part, raw(s), s.size(), 0, 0, cv::INTER_NEAREST);
			else
				part.copyTo(raw(s));
		}
	}
	for (std::size_t i = 0; i < dets.size(); i++)
	{
		const auto& d = dets[i];
		if (onlyDynamic && !d.dynamic) continue;
		const cv::Rect box = coveringRect(d.box, 0, 1, image);
		if (box.area() <= 0) continue;
		TMaskRegion reg;
		reg.detection = held[i] ? -1 : static_cast<int>(i);
		reg.held = held[i];
		cv::Mat obj;
		cv::Rect at;
		bool ok = false;
		if (opts_.method != "box")
		{
			const cv::Rect small =
				cv::Rect(box.x / f, box.y / f, std::max(1, box.width / f), std::max(1, box.height / f)) &
				cv::Rect(0, 0, raw.cols, raw.rows);
			cv::Mat objS;
			cv::Rect atS;
			ok = small.area() > 0 && fillBox(raw, small, objS, atS, reg.seed);
			if (ok && opts_.dilatePixels > 0)
			{
				// Grow the object by dilatePixels (full-resolution pixels), at the fill resolution: the
				// mask is then scaled up, so this costs 1/f^2 of a full-resolution dilation.
				const int rad = (opts_.dilatePixels + f - 1) / f;
				const cv::Rect grown = cv::Rect(atS.x - rad, atS.y - rad, atS.width + 2 * rad, atS.height + 2 * rad) &
									   cv::Rect(0, 0, raw.cols, raw.rows);
				cv::Mat big = cv::Mat::zeros(grown.size(), CV_8U);
				objS.copyTo(big(atS - grown.tl()));
				cv::dilate(big, big, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * rad + 1, 2 * rad + 1)));
				objS = big;
				atS = grown;
			}
			if (ok && f > 1)
			{
				at = cv::Rect(atS.x * f, atS.y * f, atS.width * f, atS.height * f) & image;
				cv::resize(objS, obj, cv::Size(atS.width * f, atS.height * f), 0, 0, cv::INTER_NEAREST);
				obj = obj(cv::Rect(0, 0, at.width, at.height));
				reg.seed *= f;
			}
			else if (ok)
			{
				at = atS;
				obj = objS;
			}
		}
		if (!ok)
		{
			if (opts_.method != "box" && !opts_.fallbackToBox)
			{
				r.regions.push_back(reg);
				continue;
			}
			at = box;
			obj = cv::Mat(box.size(), CV_8U, cv::Scalar(255));
			reg.usedBox = true;
		}
		reg.pixels = static_cast<std::size_t>(cv::countNonZero(obj));
		r.mask(at).setTo(255, obj);
		r.classLabels(at).setTo(d.classId + 1, obj);
		r.instanceLabels(at).setTo(static_cast<int>(i) + 1, obj);
		r.regions.push_back(reg);
	}
	return r;
}

std::vector<bool> CDynamicObjectMasker::classifyKeypoints(const std::vector<cv::KeyPoint>& kps, const cv::Mat& mask)
{
	std::vector<bool> dyn(kps.size(), false);
	for (std::size_t i = 0; i < kps.size(); i++)
	{
		const int x = static_cast<int>(std::lround(kps[i].pt.x)), y = static_cast<int>(std::lround(kps[i].pt.y));
		dyn[i] = !mask.empty() && x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask.at<uchar>(y, x) != 0;
	}
	return dyn;
}
}  // namespace mrpt_yesslam
