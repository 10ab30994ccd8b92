// Fuzz target: INI and YAML configs through MRPT's parsers, our validation and a TOptions load.
// The first byte picks the format.
#include <cstdint>
#include <sstream>
#include <string>

#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/Error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	using namespace mrpt_yesslam;
	if (size < 1) return 0;
	const bool yaml = data[0] & 1;
	const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
	try
	{
		auto cfg = parseConfigText(text, yaml, "fuzz.ini");
		validateConfigSection(*cfg, "fuzz.ini", "Input", CInputSource::TOptions::configKeys());
		CInputSource::TOptions o;
		o.loadFromConfigFile(*cfg, "Input");
		std::ostringstream ss;
		o.dumpToTextStream(ss);
	}
	catch (const InputError&)
	{
	}
	return 0;
}
