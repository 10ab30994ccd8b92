#pragma once
// Decoding the PNG images of recorded RGB-D datasets (TUM, Bonn, our own folders): 8-bit colour
// and 16-bit depth. Replaying a dataset spent a sixth of the CPU in libpng's zlib inflate (issue
// 41's profile); libdeflate inflates the same streams about twice as fast. Only the kinds those
// datasets hold are decoded here, to the same pixels cv::imread gives; anything else is left to
// OpenCV (readImageFile).
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

namespace mrpt_yesslam
{
/** What decodePng made of a buffer: the image, or "not a kind decoded here" (handled false: use a
 * general decoder), or a damaged PNG (error says how). */
struct TPngDecodeResult
{
	bool handled = false;  //!< a PNG of a kind decoded here (image or error is set)
	cv::Mat image;         //!< as cv::imdecode gives it with the same flags
	std::string error;     //!< why a PNG of a handled kind could not be decoded
};

/** Decodes a whole PNG file held in memory when it is non-interlaced 8-bit RGB (cv::IMREAD_COLOR
 * or cv::IMREAD_UNCHANGED: BGR, CV_8UC3), 8-bit grey or 16-bit grey (cv::IMREAD_UNCHANGED: CV_8UC1,
 * CV_16UC1), without a tRNS chunk; the chunk CRCs of IHDR and IDAT and the zlib checksum are
 * checked, as libpng does. Any other file or flag: handled = false. */
TPngDecodeResult decodePng(const std::uint8_t* data, std::size_t size, int imreadFlags);

/** Reads an image file as cv::imread(path, flags) would (decodePng for the PNG kinds above, OpenCV
 * for the rest); throws InputError(path, "cannot decode WHAT (...)") for a missing, truncated or
 * corrupt file instead of returning an empty image. */
cv::Mat readImageFile(const std::string& path, int imreadFlags, const std::string& what);
}  // namespace mrpt_yesslam
