#include "mrpt_yesslam/util/Error.h"

#include <cstdio>
#include <sstream>

namespace mrpt_yesslam
{
std::string exceptionSummary(const std::string& what)
{
	std::istringstream ss(what);
	std::string line, first;
	while (std::getline(ss, line))
	{
		while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
		const auto b = line.find_first_not_of(' ');
		if (b == std::string::npos) continue;
		line = line.substr(b);
		if (line.rfind("==== MRPT exception", 0) == 0) continue;
		if (line.rfind("Message:", 0) == 0)
		{
			const auto m = line.find_first_not_of(' ', 8);
			return m == std::string::npos ? std::string() : line.substr(m);
		}
		if (first.empty()) first = line;
	}
	return first.empty() ? std::string("unknown error") : first;
}
namespace
{
std::string& programName()
{
	static std::string name = "mrpt_yesslam";
	return name;
}
}  // namespace

void setProgramName(const std::string& name)
{
	programName() = name;
}

void printWarning(const std::string& message)
{
	std::string m = message;
	for (std::size_t p = 0; (p = m.find('\n', p)) != std::string::npos;) m.replace(p, 1, "; ");
	std::fprintf(stderr, "%s: warning: %s\n", programName().c_str(), m.c_str());
}
}  // namespace mrpt_yesslam
