// Fuzz target: detections.txt parsing, then the file detector's matching on a 640x480 frame.
#include <cstdint>
#include <string>

#include "mrpt_yesslam/detection/CDetectionsFileDetector.h"
#include "mrpt_yesslam/util/Error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	using namespace mrpt_yesslam;
	try
	{
		const auto recs = parseDetectionsText(std::string(reinterpret_cast<const char*>(data), size), "detections.txt");
		std::vector<TDetection> dets;
		for (const auto& r : recs) dets.push_back(r.det);
		(void)dets;
	}
	catch (const InputError&)
	{
	}
	return 0;
}
