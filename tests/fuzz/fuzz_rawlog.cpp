// Fuzz target: rawlog files (gz or plain) read to the end through CRawlogSource. MRPT's
// deserialiser reads from a file, so each input is written to a per-process scratch file.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

#include "mrpt_yesslam/io/CRawlogSource.h"
#include "mrpt_yesslam/util/Error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	using namespace mrpt_yesslam;
	static const std::string path = "/tmp/yesslam_fuzz_rawlog_" + std::to_string(::getpid()) + ".rawlog";
	{
		std::ofstream f(path, std::ios::binary | std::ios::trunc);
		f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
	}
	try
	{
		CRawlogSource src(path);
		for (int i = 0; i < 1000 && src.next(); i++)
		{
		}
	}
	catch (const InputError&)
	{
	}
	std::remove(path.c_str());
	return 0;
}
