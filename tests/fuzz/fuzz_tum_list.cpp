// Fuzz target: TUM image lists (rgb.txt, depth.txt), then association of two lists cut from it.
#include <cstdint>
#include <string>

#include "mrpt_yesslam/io/Association.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"
#include "mrpt_yesslam/util/Error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	using namespace mrpt_yesslam;
	const std::string text(reinterpret_cast<const char*>(data), size);
	try
	{
		const auto l = parseTumFileList(text, "rgb.txt");
		std::vector<double> a, b;
		for (std::size_t i = 0; i < l.size(); i++) (i % 2 ? a : b).push_back(l[i].t);
		associateTimestamps(a, b);
	}
	catch (const InputError&)
	{
	}
	return 0;
}
