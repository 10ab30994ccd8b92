// Fuzz target: PNG files through the dataset decoder (io/PngDecoder.h), as colour and as depth. A
// decoded image must have the header's size and the kind asked for; anything else is refused or
// left to OpenCV, never a crash.
#include <cstdint>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>

#include "mrpt_yesslam/io/PngDecoder.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	using namespace mrpt_yesslam;
	for (const int flags : {cv::IMREAD_COLOR, cv::IMREAD_UNCHANGED})
	{
		const TPngDecodeResult r = decodePng(data, size, flags);
		if (!r.handled || !r.error.empty()) continue;
		// Decoded: the header's width and height (bytes 16-23), one of the three kinds.
		const auto be32 = [&](std::size_t at) {
			return (uint32_t(data[at]) << 24) | (uint32_t(data[at + 1]) << 16) | (uint32_t(data[at + 2]) << 8) |
				   data[at + 3];
		};
		const int t = r.image.type();
		if (r.image.empty() || static_cast<uint32_t>(r.image.cols) != be32(16) ||
			static_cast<uint32_t>(r.image.rows) != be32(20) || (t != CV_8UC3 && t != CV_8UC1 && t != CV_16UC1) ||
			(flags == cv::IMREAD_COLOR && t != CV_8UC3))
			std::abort();
	}
	return 0;
}
