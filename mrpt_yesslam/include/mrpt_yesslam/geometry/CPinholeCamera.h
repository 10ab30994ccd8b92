#pragma once
// The one camera model of the system: a pinhole with OpenCV/MRPT's radial-tangential distortion
// (k1 k2 p1 p2 k3). Keypoints are undistorted once, when a frame is built; from then on tracking,
// matching, bundle adjustment and the map work in undistorted pixels with project()/backProject(),
// so that the formula exists once and cannot drift between stages.
#include <mrpt/img/TCamera.h>

#include <opencv2/core.hpp>
#include <vector>

namespace mrpt_yesslam
{
/** Pinhole projection, back-projection and undistortion for one set of intrinsics. */
class CPinholeCamera
{
   public:
	CPinholeCamera() = default;
	/** Takes fx, fy, cx, cy and the distortion of `K` (image size too). */
	explicit CPinholeCamera(const mrpt::img::TCamera& K)
		: fx_(K.fx()),
		  fy_(K.fy()),
		  cx_(K.cx()),
		  cy_(K.cy()),
		  width_(static_cast<int>(K.ncols)),
		  height_(static_cast<int>(K.nrows))
	{
		for (int i = 0; i < 5; i++) dist_[i] = K.dist[i];
	}

	double fx() const { return fx_; }
	double fy() const { return fy_; }
	double cx() const { return cx_; }
	double cy() const { return cy_; }
	int width() const { return width_; }
	int height() const { return height_; }

	/** Undistorted pixel of camera-frame point (x, y, z); false behind the camera (z <= 0). */
	bool project(double x, double y, double z, double& u, double& v) const
	{
		if (!(z > 0)) return false;
		u = fx_ * x / z + cx_;
		v = fy_ * y / z + cy_;
		return true;
	}
	/** Whether an (undistorted) pixel lies inside the image. */
	bool inImage(double u, double v) const { return u >= 0 && v >= 0 && u < width_ && v < height_; }
	/** Camera-frame point of undistorted pixel (u, v) at depth z. */
	cv::Point3d backProject(double u, double v, double z) const
	{
		return {(u - cx_) * z / fx_, (v - cy_) * z / fy_, z};
	}

	/** Whether any distortion coefficient is non-zero. */
	bool distorted() const { return dist_[0] != 0 || dist_[1] != 0 || dist_[2] != 0 || dist_[3] != 0 || dist_[4] != 0; }
	/** Undistorted pixel positions of raw (distorted) ones, in place; nothing to do without distortion. */
	void undistort(std::vector<cv::Point2f>& pixels) const;
	/** The raw (distorted) pixel of an undistorted one: where it lies in the images as recorded. */
	cv::Point2d distort(double u, double v) const
	{
		if (!distorted()) return {u, v};
		const double x = (u - cx_) / fx_, y = (v - cy_) / fy_, r2 = x * x + y * y;
		const double radial = 1 + r2 * (dist_[0] + r2 * (dist_[1] + r2 * dist_[4]));
		const double xd = x * radial + 2 * dist_[2] * x * y + dist_[3] * (r2 + 2 * x * x);
		const double yd = y * radial + dist_[2] * (r2 + 2 * y * y) + 2 * dist_[3] * x * y;
		return {fx_ * xd + cx_, fy_ * yd + cy_};
	}

   private:
	double fx_ = 1, fy_ = 1, cx_ = 0, cy_ = 0;
	int width_ = 0, height_ = 0;
	double dist_[5] = {0, 0, 0, 0, 0};
};
}  // namespace mrpt_yesslam
