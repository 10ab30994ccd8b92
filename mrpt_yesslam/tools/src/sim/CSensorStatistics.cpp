#include "mrpt_yesslam/sim/CSensorStatistics.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

namespace mrpt_yesslam
{
namespace
{
double median(std::vector<double> v)
{
	if (v.empty()) return 0;
	const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
	std::nth_element(v.begin(), mid, v.end());
	return *mid;
}
constexpr double kBin0 = 0.5, kBinW = 0.5;
}  // namespace

void CSensorStatistics::addFrame(const cv::Mat& bgr, const cv::Mat& depth)
{
	CV_Assert(depth.type() == CV_32F);
	frames_++;
	const int valid = cv::countNonZero(depth > 0);
	validSum_ += static_cast<double>(valid) / static_cast<double>(depth.total());
	valid_ += static_cast<std::size_t>(valid);

	// Plane residuals of P x P patches with full depth, in pixel coordinates (a small patch of a
	// smooth surface is a plane in (u, v, z) as well as in space): 8 px for the sensor's
	// pixel-to-pixel noise, 32 px for errors that are smooth over tens of pixels (a structured-light
	// sensor's correlation windows), which the small patches cannot see and which do not average
	// out over the keypoints of a frame.
	const auto patches = [&](int P, std::vector<std::vector<double>>& out)
	{
		Eigen::MatrixXd A(P * P, 3);
		for (int y = 0; y < P; y++)
			for (int x = 0; x < P; x++) A.row(y * P + x) << x - (P - 1) / 2.0, y - (P - 1) / 2.0, 1.0;
		const Eigen::MatrixXd pinv = (A.transpose() * A).inverse() * A.transpose();
		Eigen::VectorXd z(P * P);
		for (int y0 = 0; y0 + P <= depth.rows; y0 += P)
			for (int x0 = 0; x0 + P <= depth.cols; x0 += P)
			{
				bool full = true;
				for (int y = 0; y < P && full; y++)
				{
					const float* row = depth.ptr<float>(y0 + y);
					for (int x = 0; x < P; x++)
					{
						if (!(row[x0 + x] > 0))
						{
							full = false;
							break;
						}
						z(y * P + x) = row[x0 + x];
					}
				}
				if (!full) continue;
				const Eigen::Vector3d plane = pinv * z;
				const double rms = std::sqrt((z - A * plane).squaredNorm() / (P * P - 3));
				const double zc = plane(2);
				if (rms > std::min(0.05, 0.1 * zc)) continue;  // an edge, not a surface
				const int bin = static_cast<int>(std::floor((zc - kBin0) / kBinW));
				if (bin >= 0 && bin < static_cast<int>(out.size())) out[static_cast<std::size_t>(bin)].push_back(rms);
			}
	};
	patches(8, residuals_);
	patches(32, residuals32_);

	// Holes of missing depth and their sizes.
	cv::Mat holes = depth <= 0, labels, comp, centroids;
	const int n = cv::connectedComponentsWithStats(holes, labels, comp, centroids, 4, CV_32S);
	for (int i = 1; i < n; i++)
	{
		const auto area = static_cast<std::size_t>(comp.at<int>(i, cv::CC_STAT_AREA));
		missing_ += area;
		if (area < 16) speckle_ += area;
	}

	// Flying pixels: between their horizontal neighbours across a jump.
	for (int y = 0; y < depth.rows; y++)
	{
		const float* r = depth.ptr<float>(y);
		for (int x = 1; x + 1 < depth.cols; x++)
		{
			const float a = r[x - 1], v = r[x], b = r[x + 1];
			if (!(a > 0 && v > 0 && b > 0)) continue;
			const float lo = std::min(a, b), hi = std::max(a, b);
			if (hi - lo > 0.1f * v && v > lo + 0.03f * v && v < hi - 0.03f * v) flying_++;
		}
	}

	cv::Mat grey;
	if (bgr.channels() == 3)
		cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
	else
		grey = bgr;
	const cv::Mat dark = darkSurfaces(grey);
	constexpr int B = 32;
	for (int y = B; y < depth.rows - B; y++)
	{
		const float* pz = depth.ptr<float>(y);
		const uchar* pd = dark.ptr<uchar>(y);
		for (int x = B; x < depth.cols - B; x++)
		{
			const bool ok = pz[x] > 0;
			if (pd[x])
				dark_++, darkValid_ += ok;
			else
				light_++, lightValid_ += ok;
		}
	}
	std::vector<cv::KeyPoint> corners;
	cv::FAST(grey, corners, 20, false);  // existence per cell; non-maximum suppression is not needed
	constexpr int C = 32;
	const int cols = (grey.cols + C - 1) / C, rows = (grey.rows + C - 1) / C;
	std::vector<char> hit(static_cast<std::size_t>(cols * rows), 0);
	for (const auto& k : corners)
		hit[static_cast<std::size_t>(static_cast<int>(k.pt.y) / C * cols + static_cast<int>(k.pt.x) / C)] = 1;
	texturedSum_ += static_cast<double>(std::count(hit.begin(), hit.end(), 1)) / static_cast<double>(hit.size());
	cv::Mat lap;
	cv::Laplacian(grey, lap, CV_64F);
	cv::Scalar mean, sd;
	cv::meanStdDev(lap, mean, sd);
	sharpness_.push_back(sd[0] * sd[0]);
	const cv::Mat N = (cv::Mat_<double>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
	cv::Mat nr;
	cv::filter2D(grey, nr, CV_64F, N);
	const cv::Rect inner(1, 1, grey.cols - 2, grey.rows - 2);
	colourNoise_.push_back(std::sqrt(M_PI / 2) * cv::norm(nr(inner), cv::NORM_L1) / (6.0 * inner.width * inner.height));
}

CSensorStatistics::TResult CSensorStatistics::result() const
{
	TResult r;
	r.frames = frames_;
	if (frames_ == 0) return r;
	r.validDepthShare = validSum_ / static_cast<double>(frames_);
	r.flyingPixelShare = valid_ ? static_cast<double>(flying_) / static_cast<double>(valid_) : 0.0;
	r.speckleHoleShare = missing_ ? static_cast<double>(speckle_) / static_cast<double>(missing_) : 0.0;
	r.darkValidShare = dark_ ? static_cast<double>(darkValid_) / static_cast<double>(dark_) : 0.0;
	r.lightValidShare = light_ ? static_cast<double>(lightValid_) / static_cast<double>(light_) : 0.0;
	r.texturedCellShare = texturedSum_ / static_cast<double>(frames_);
	r.sharpness = median(sharpness_);
	r.colourNoise = median(colourNoise_);
	double num = 0, den = 0;
	for (std::size_t b = 0; b < residuals_.size(); b++)
	{
		TNoiseBin n;
		n.zMin = kBin0 + kBinW * static_cast<double>(b);
		n.zMax = n.zMin + kBinW;
		n.patches = residuals_[b].size();
		n.medianResidual = median(residuals_[b]);
		n.patches32 = residuals32_[b].size();
		n.medianResidual32 = median(residuals32_[b]);
		r.noise.push_back(n);
		if (n.patches >= 20)
		{
			// sigma = k z^2 through the bins' medians, each bin weighted by its patch count.
			const double zc = 0.5 * (n.zMin + n.zMax), z2 = zc * zc, w = static_cast<double>(n.patches);
			num += w * z2 * n.medianResidual;
			den += w * z2 * z2;
		}
	}
	r.noiseK = den > 0 ? num / den : 0.0;
	return r;
}

cv::Mat CSensorStatistics::darkSurfaces(const cv::Mat& grey)
{
	cv::Mat window, dark;
	cv::blur(grey, window, cv::Size(9, 9));
	cv::compare(window, 60, dark, cv::CMP_LT);
	return dark;
}

std::string CSensorStatistics::format(const TResult& r)
{
	std::string out;
	char b[256];
	std::snprintf(b, sizeof(b),
				  "frames: %zu\nvalid_depth_share: %.4f\nflying_pixel_share: %.5f\nspeckle_hole_share: "
				  "%.4f\ndark_valid_share: %.4f\n"
				  "light_valid_share: %.4f\ntextured_cell_share: %.4f\nsharpness: %.1f\ncolour_noise: %.2f\n",
				  r.frames, r.validDepthShare, r.flyingPixelShare, r.speckleHoleShare, r.darkValidShare,
				  r.lightValidShare, r.texturedCellShare, r.sharpness, r.colourNoise);
	out += b;
	for (const auto& n : r.noise)
	{
		std::snprintf(b, sizeof(b), "noise_%.1f_%.1f_mm: %.2f (%zu patches)\n", n.zMin, n.zMax, 1000 * n.medianResidual,
					  n.patches);
		out += b;
		std::snprintf(b, sizeof(b), "noise32_%.1f_%.1f_mm: %.2f (%zu patches)\n", n.zMin, n.zMax,
					  1000 * n.medianResidual32, n.patches32);
		out += b;
	}
	std::snprintf(b, sizeof(b), "noise_k: %.5f\n", r.noiseK);
	out += b;
	return out;
}
}  // namespace mrpt_yesslam
