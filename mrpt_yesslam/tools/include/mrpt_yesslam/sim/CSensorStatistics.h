#pragma once
// What a sequence's frames look like to SLAM, so that the simulator can be held against real
// sensors (issue 27): depth noise against distance, valid depth, flying pixels at depth edges,
// texture and sharpness of the colour image. Measured the same way on any RGB-D frames, simulated
// or real, with no ground truth:
// - depth noise: every 8 x 8 patch with full depth gets a least-squares plane; the RMS residual is
//   the noise of a smooth surface at the patch's depth (patches on edges, residual above 5 cm or
//   10 % of the depth, are left out); medians per depth bin, and k of sigma = k z^2 fitted to them.
//   The same on 32 x 32 patches shows errors smooth over tens of pixels, which 8 x 8 ones cannot.
// - flying pixels: valid pixels lying between their left and right neighbours across a jump of
//   more than 10 % of the depth, at least 3 % from both (the mixed returns of a structured-light
//   sensor at silhouettes).
// - speckled holes: the share of missing depth pixels lying in holes (4-connected) of under 16
//   pixels. A structured-light sensor matches windows of its pattern, so where too little of it
//   comes back (dark or shiny surfaces) it loses depth in blobs, not pixel by pixel; speckle
//   breaks the 4-neighbour flood fill of the masker (eq. 4-5) at every step.
// - valid depth on dark and on light surfaces, 32 px or more from the image border (registered
//   depth leaves the border empty): dark where the 9 x 9 window round the pixel (a structured-light
//   correlation window) averages under 60 grey levels.
// - texture: the share of 32 x 32 cells with a FAST corner at threshold 20; sharpness: the
//   median over frames of the variance of the grey image's Laplacian (motion blur lowers it; strong
//   edges raise it); colour noise: Immerkaer's estimate of the grey image's noise (J. Immerkaer,
//   "Fast noise variance estimation", CVIU 1996: a mask blind to planes and lines of grey), median
//   over frames, in grey levels (texture adds to it: an upper bound).
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace mrpt_yesslam
{
/** Accumulates per-frame sensor statistics over a sequence. */
class CSensorStatistics
{
   public:
	/** One depth bin of the noise curve. */
	struct TNoiseBin
	{
		double zMin = 0, zMax = 0;
		std::size_t patches = 0;
		double medianResidual = 0;  //!< metres, 8 x 8 patches
		std::size_t patches32 = 0;
		double medianResidual32 = 0;  //!< metres, 32 x 32 patches (errors smooth over tens of pixels show here)
	};
	/** The sequence's statistics. */
	struct TResult
	{
		std::size_t frames = 0;
		double validDepthShare = 0;    //!< mean over frames of valid depth pixels / all pixels
		double flyingPixelShare = 0;   //!< flying pixels / valid pixels
		double speckleHoleShare = 0;   //!< missing pixels in holes under 16 px / missing pixels
		double darkValidShare = 0;     //!< valid depth on dark surfaces, away from the border
		double lightValidShare = 0;    //!< valid depth on light surfaces, away from the border
		double texturedCellShare = 0;  //!< mean over frames
		double sharpness = 0;          //!< median Laplacian variance (grey levels^2)
		double colourNoise = 0;        //!< median Immerkaer noise sigma of the grey image (grey levels)
		std::vector<TNoiseBin> noise;  //!< 0.5-1, 1-1.5, ... 4.5-5 m
		double noiseK = 0;             //!< k of sigma = k z^2, least squares over the bins' medians (0 without patches)
	};

	/** Adds one frame: colour (BGR or grey) and depth in metres (CV_32F, 0 = none). */
	void addFrame(const cv::Mat& bgr, const cv::Mat& depthMetres);
	/** The statistics of the frames added so far. */
	TResult result() const;
	/** The result as "key: value" lines, noise bins as noise_<zmin>_<zmax>_mm. */
	static std::string format(const TResult& r);
	/** Where a surface is dark to a structured-light sensor (CV_8U, 255): the 9 x 9 window round
	 * the pixel (its correlation window) averages under 60 grey levels. The one definition, for
	 * the statistics and for the simulator's real sensor, which must agree. */
	static cv::Mat darkSurfaces(const cv::Mat& grey);

   private:
	std::size_t frames_ = 0;
	double validSum_ = 0, texturedSum_ = 0;
	std::size_t flying_ = 0, valid_ = 0, missing_ = 0, speckle_ = 0;
	std::size_t dark_ = 0, darkValid_ = 0, light_ = 0, lightValid_ = 0;
	std::vector<double> sharpness_, colourNoise_;
	std::vector<std::vector<double>> residuals_ = std::vector<std::vector<double>>(9);
	std::vector<std::vector<double>> residuals32_ = std::vector<std::vector<double>>(9);
};
}  // namespace mrpt_yesslam
