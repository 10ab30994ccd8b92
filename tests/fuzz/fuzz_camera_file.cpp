// Fuzz target: camera files ("fx fy cx cy [w h [depth_scale]]" + distortion line).
#include <cstdint>
#include <string>

#include "mrpt_yesslam/io/RgbdCamera.h"
#include "mrpt_yesslam/util/Error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	using namespace mrpt_yesslam;
	try
	{
		parseCameraFile(std::string(reinterpret_cast<const char*>(data), size), "camera.txt");
	}
	catch (const InputError&)
	{
	}
	return 0;
}
