#include "mrpt_yesslam/sim/SimSensorModel.h"

#include <opencv2/imgproc.hpp>

#include "mrpt_yesslam/sim/CSensorStatistics.h"

namespace mrpt_yesslam
{
// Kinect-like depth noise (Khoshelham & Elberink 2012): sigma_z = 1.425e-3 z^2, disparity quantised
// to 1/8 pixel, no depth nearer than 0.5 m or beyond 4.5 m, missing depth at depth edges and in
// small holes.
// The real sensor (--real-sensor), fitted to the frames of ../shared beside ours (bench/bench_realism.sh;
// docs/benchmarks.md, "Simulator against real frames"). Its error is not white: a structured-light sensor matches 9 x 9
// windows of its pattern, so neighbouring pixels share it, and it does not average out over a frame's keypoints.
// Modelled as a smooth field (1/16 of the resolution, bilinear) beside a smaller per-pixel part.
// Where depth is missing: a window either matches or not, so depth is lost in blobs, not pixel by pixel; the dropout
// draws come from a smooth field (`drop`, uniform on [0, 1] at every pixel). Surfaces dark to the colour camera lose
// more than light ones: dark 9 x 9 windows lose 10 %.
// Most missing depth is the border that registering depth to the colour camera leaves empty (at 640 x 480: 20 px left,
// 22 right, 6 top, 18 bottom, ragged). Dropping dark pixels one by one, as the model did before, left speckle and
// stopped the masker's fill (eq. 4-5) at its seed on dark clothes.
// No projector shadow is modelled: the real Bonn frames lose depth on both sides of a person before a wall alike, not
// in a band on one side as a shadow would (their depth is registered to the colour camera); the dropouts at depth edges
// (addDepthNoise) cover it.
void addRealSensorDepthError(cv::Mat& z, const cv::Mat& grey, const cv::Mat& drop, std::mt19937& rng)
{
	const cv::Mat dark = CSensorStatistics::darkSurfaces(grey);
	cv::RNG cvRng(rng());
	cv::Mat coarse(z.rows / 16 + 1, z.cols / 16 + 1, CV_32F), field;
	cvRng.fill(coarse, cv::RNG::NORMAL, 0.0, 1.0);
	cv::resize(coarse, field, z.size(), 0, 0, cv::INTER_LINEAR);
	// Registration border at 640 x 480, scaled to other sizes; ragged by up to 4 px.
	const float sx = z.cols / 640.0f, sy = z.rows / 480.0f;
	const float left = 20 * sx, right = z.cols - 22 * sx, top = 6 * sy, bottom = z.rows - 18 * sy;
	for (int y = 0; y < z.rows; y++)
	{
		float* pz = z.ptr<float>(y);
		const float *pf = field.ptr<float>(y), *pu = drop.ptr<float>(y);
		const uchar* pd = dark.ptr<uchar>(y);
		for (int x = 0; x < z.cols; x++)
		{
			if (pz[x] <= 0) continue;
			const float rag = 4 * pu[x], fx = static_cast<float>(x), fy = static_cast<float>(y);
			const bool border = fx < left - rag || fx >= right + rag || fy < top - rag || fy >= bottom + rag;
			if (border || (pd[x] && pu[x] < 0.1f))  // dark: too little of the pattern comes back
			{
				pz[x] = 0;
				continue;
			}
			pz[x] += 2.0e-3f * pz[x] * pz[x] * pf[x];
		}
	}
}

// Random numbers uniform on [0, 1] at every pixel but alike over about `cell` pixels: a Gaussian
// field on a coarse grid, interpolated, scaled to unit variance and mapped through the normal CDF.
cv::Mat coherentUniform(cv::Size size, int cell, std::mt19937& rng)
{
	cv::RNG cvRng(rng());
	cv::Mat coarse(size.height / cell + 2, size.width / cell + 2, CV_32F), field;
	cvRng.fill(coarse, cv::RNG::NORMAL, 0.0, 1.0);
	// Cubic interpolation keeps more of the variance than bilinear and leaves no grid pattern.
	cv::resize(coarse, field, cv::Size(coarse.cols * cell, coarse.rows * cell), 0, 0, cv::INTER_CUBIC);
	field = field(cv::Rect(cell / 2, cell / 2, size.width, size.height)).clone();
	cv::Scalar mean, sd;
	cv::meanStdDev(field, mean, sd);
	const float m = static_cast<float>(mean[0]), k = static_cast<float>(1.0 / (std::max(sd[0], 1e-6) * std::sqrt(2.0)));
	field.forEach<float>([&](float& v, const int*) { v = 0.5f * (1.0f + std::erf((v - m) * k)); });
	return field;
}

// `drop`: the dropout draws at depth edges (uniform on [0, 1]); per pixel when empty.
// `edgeRadius`: how far from a depth edge depth may be lost (1 px for the Kinect model; 3 px for the real sensor, whose
// frames lose a wider band across a person's silhouette).
void addDepthNoise(cv::Mat& z, std::mt19937& rng, const TRgbdCamera& cam, float whiteK, const cv::Mat& drop,
				   int edgeRadius)
{
	const float fb = static_cast<float>(cam.intrinsics.fx() * 0.075);  // focal length x baseline
	// Depth edge: a valid neighbour (within edgeRadius) differs by more than 8 %: the sensor often
	// sees nothing there. Largest and smallest valid neighbour by dilation and erosion (missing
	// depth counts as +inf for the smallest; pixels outside the image are ignored by both).
	cv::Mat mx, mn, zInf = z.clone();
	zInf.setTo(std::numeric_limits<float>::infinity(), z <= 0);
	const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * edgeRadius + 1, 2 * edgeRadius + 1));
	cv::dilate(z, mx, kernel);
	cv::erode(zInf, mn, kernel);
	// Per-pixel random numbers drawn in bulk (OpenCV's generator, seeded from the frame's).
	cv::RNG cvRng(rng());
	cv::Mat gauss(z.size(), CV_32F), unif(z.size(), CV_32F);
	cvRng.fill(gauss, cv::RNG::NORMAL, 0.0, 1.0);
	if (drop.empty())
		cvRng.fill(unif, cv::RNG::UNIFORM, 0.0, 1.0);
	else
		unif = drop;
	for (int y = 0; y < z.rows; y++)
	{
		float* pz = z.ptr<float>(y);
		const float *pmx = mx.ptr<float>(y), *pmn = mn.ptr<float>(y), *pg = gauss.ptr<float>(y),
					*pu = unif.ptr<float>(y);
		for (int x = 0; x < z.cols; x++)
		{
			float v = pz[x];
			if (v <= 0) continue;
			const bool edge = pmx[x] > 1.08f * v || pmn[x] < 0.92f * v;
			if (v < 0.5f || v > 4.5f || (edge && pu[x] < 0.7f))
			{
				pz[x] = 0;
				continue;
			}
			v += whiteK * v * v * pg[x];
			const float disp = std::nearbyint(fb / v * 8.0f) / 8.0f;
			pz[x] = disp > 0 ? fb / disp : 0;
		}
	}
	// Small holes.
	std::uniform_int_distribution<int> px(0, z.cols - 1), py(0, z.rows - 1), rad(1, 4);
	for (int i = 0; i < 40; i++) cv::circle(z, {px(rng), py(rng)}, rad(rng), cv::Scalar(0), cv::FILLED);
}
}  // namespace mrpt_yesslam
