#include "mrpt_yesslam/eval/TrajectoryPlot.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
namespace
{
double niceStep(double range, int targetTicks)
{
	const double raw = range / std::max(1, targetTicks);
	const double p = std::pow(10.0, std::floor(std::log10(raw)));
	for (double m : {1.0, 2.0, 5.0, 10.0})
		if (m * p >= raw) return m * p;
	return 10 * p;
}

cv::Vec3b colourFor(double e, double lo, double hi)
{
	// OpenCV's jet map, its 256 colours made once: applyColorMap builds its table on every call,
	// which was most of a plot's time (0.2 s of a 120-frame run's outputs).
	static const cv::Mat3b jet = []
	{
		cv::Mat1b ramp(256, 1);
		for (int i = 0; i < 256; i++) ramp(i, 0) = static_cast<uchar>(i);
		cv::Mat3b c;
		cv::applyColorMap(ramp, c, cv::COLORMAP_JET);
		return c;
	}();
	const double f = hi > lo ? std::clamp((e - lo) / (hi - lo), 0.0, 1.0) : 0.0;
	return jet(static_cast<int>(std::lround(f * 255)), 0);
}
}  // namespace

void plotAteTopDown(const TAteResult& ate, const TTrajectory& gtFull, const std::string& pngPath,
					const std::string& title, int W, int H)
{
	// Pick the plane: the two axes with the largest ground-truth extent.
	Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
	auto grow = [&](const Eigen::Vector3d& p)
	{
		lo = lo.cwiseMin(p);
		hi = hi.cwiseMax(p);
	};
	for (const auto& p : gtFull) grow(Eigen::Vector3d(p.tx, p.ty, p.tz));
	for (const auto& p : ate.estAligned) grow(p);
	const Eigen::Vector3d ext = hi - lo;
	int ax[3] = {0, 1, 2};
	std::sort(ax, ax + 3, [&](int a, int b) { return ext[a] > ext[b]; });
	int a0 = std::min(ax[0], ax[1]), a1 = std::max(ax[0], ax[1]);
	const char* names = "xyz";

	// The right margin holds the colour bar and the legend, whose widest line sets it (a fixed 150 px
	// cut "(Sim3-aligned)" at the picture's edge).
	int base = 0;
	const int legendText = std::max(cv::getTextSize("(Sim3-aligned)", cv::FONT_HERSHEY_SIMPLEX, 0.42, 1, &base).width,
									cv::getTextSize("ground truth", cv::FONT_HERSHEY_SIMPLEX, 0.42, 1, &base).width);
	const int left = 90, right = std::max(150, 30 + 26 + legendText + 12), top = 60, bottom = 70;
	const int pw = W - left - right, ph = H - top - bottom;
	double spanX = std::max(ext[a0], 1e-3), spanY = std::max(ext[a1], 1e-3);
	const double s = 0.92 * std::min(pw / spanX, ph / spanY);  // pixels per metre, equal aspect
	const double cxm = 0.5 * (lo[a0] + hi[a0]), cym = 0.5 * (lo[a1] + hi[a1]);
	auto toPx = [&](double x, double y)
	{ return cv::Point2d(left + pw / 2.0 + (x - cxm) * s, top + ph / 2.0 - (y - cym) * s); };

	cv::Mat3b img(H, W, cv::Vec3b(255, 255, 255));
	cv::rectangle(img, cv::Rect(left, top, pw, ph), cv::Scalar(0, 0, 0), 1);
	// Metre grid and tick labels.
	const double xmin = cxm - pw / 2.0 / s, xmax = cxm + pw / 2.0 / s;
	const double ymin = cym - ph / 2.0 / s, ymax = cym + ph / 2.0 / s;
	const double step = niceStep(std::max(xmax - xmin, ymax - ymin), 8);
	char buf[64];
	for (double x = std::ceil(xmin / step) * step; x <= xmax; x += step)
	{
		const int px = static_cast<int>(std::lround(toPx(x, 0).x));
		cv::line(img, {px, top}, {px, top + ph}, cv::Scalar(225, 225, 225), 1);
		std::snprintf(buf, sizeof(buf), "%.2f", std::abs(x) < 1e-12 ? 0.0 : x);
		cv::putText(img, buf, {px - 20, top + ph + 22}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1,
					cv::LINE_AA);
	}
	for (double y = std::ceil(ymin / step) * step; y <= ymax; y += step)
	{
		const int py = static_cast<int>(std::lround(toPx(0, y).y));
		cv::line(img, {left, py}, {left + pw, py}, cv::Scalar(225, 225, 225), 1);
		std::snprintf(buf, sizeof(buf), "%.2f", std::abs(y) < 1e-12 ? 0.0 : y);
		cv::putText(img, buf, {left - 55, py + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
	}
	cv::rectangle(img, cv::Rect(left, top, pw, ph), cv::Scalar(0, 0, 0), 1);
	std::snprintf(buf, sizeof(buf), "%c [m]", names[a0]);
	cv::putText(img, buf, {left + pw / 2 - 20, H - 20}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 1,
				cv::LINE_AA);
	std::snprintf(buf, sizeof(buf), "%c [m]", names[a1]);
	cv::putText(img, buf, {10, top - 15}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
	cv::putText(img, title, {left, 30}, cv::FONT_HERSHEY_SIMPLEX, 0.65, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);

	// Ground truth, then the estimate coloured by error.
	const TTrajectory gtSorted = uniqueSortedByTime(gtFull);
	for (std::size_t i = 1; i < gtSorted.size(); i++)
	{
		const double p0[3] = {gtSorted[i - 1].tx, gtSorted[i - 1].ty, gtSorted[i - 1].tz};
		const double p1[3] = {gtSorted[i].tx, gtSorted[i].ty, gtSorted[i].tz};
		cv::line(img, toPx(p0[a0], p0[a1]), toPx(p1[a0], p1[a1]), cv::Scalar(90, 90, 90), 2, cv::LINE_AA);
	}
	const double eLo = ate.stats.min, eHi = std::max(ate.stats.max, ate.stats.min + 1e-9);
	for (std::size_t i = 0; i < ate.estAligned.size(); i++)
	{
		const auto& p = ate.estAligned[i];
		const cv::Vec3b c = colourFor(ate.errors[i], eLo, eHi);
		const cv::Scalar col(c[0], c[1], c[2]);
		if (i > 0)
		{
			const auto& q = ate.estAligned[i - 1];
			cv::line(img, toPx(q[a0], q[a1]), toPx(p[a0], p[a1]), col, 2, cv::LINE_AA);
		}
		cv::circle(img, toPx(p[a0], p[a1]), 2, col, cv::FILLED, cv::LINE_AA);
	}

	// Colour bar with the error range in metres.
	const int bx = left + pw + 30, by = top + 40, bw = 20, bh = ph - 140;
	for (int k = 0; k < bh; k++)
	{
		const double e = eHi - (eHi - eLo) * k / std::max(1, bh - 1);
		const cv::Vec3b c = colourFor(e, eLo, eHi);
		cv::line(img, {bx, by + k}, {bx + bw, by + k}, cv::Scalar(c[0], c[1], c[2]), 1);
	}
	cv::rectangle(img, cv::Rect(bx, by, bw, bh), cv::Scalar(0, 0, 0), 1);
	cv::putText(img, "ATE [m]", {bx - 10, by - 12}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
	for (int k = 0; k <= 4; k++)
	{
		const double e = eHi - (eHi - eLo) * k / 4.0;
		std::snprintf(buf, sizeof(buf), "%.4f", e);
		cv::putText(img, buf, {bx + bw + 6, by + k * (bh - 1) / 4 + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.42,
					cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
	}
	// Legend.
	const int ly = by + bh + 35;
	cv::line(img, {bx - 10, ly}, {bx + 20, ly}, cv::Scalar(90, 90, 90), 2, cv::LINE_AA);
	cv::putText(img, "ground truth", {bx + 26, ly + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.42, cv::Scalar(0, 0, 0), 1,
				cv::LINE_AA);
	cv::line(img, {bx - 10, ly + 25}, {bx + 20, ly + 25}, cv::Scalar(255, 0, 0), 2, cv::LINE_AA);
	cv::putText(img, "estimate", {bx + 26, ly + 30}, cv::FONT_HERSHEY_SIMPLEX, 0.42, cv::Scalar(0, 0, 0), 1,
				cv::LINE_AA);
	cv::putText(img, ate.alignment.sim3 ? "(Sim3-aligned)" : "(SE3-aligned)", {bx + 26, ly + 48},
				cv::FONT_HERSHEY_SIMPLEX, 0.42, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
	std::snprintf(buf, sizeof(buf), "ATE RMSE %.4f m, %zu pairs", ate.stats.rmse, ate.stats.n);
	cv::putText(img, buf, {left, 50}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);

	writeImageAtomically(pngPath, img);
}
}  // namespace mrpt_yesslam
