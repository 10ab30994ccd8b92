#include "mrpt_yesslam/util/TextParsing.h"

#include <cstdio>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
std::string readTextFile(const std::string& path)
{
	namespace fs = std::filesystem;
	std::error_code ec;
	if (!fs::exists(path, ec)) throw InputError(path, "file not found");
	if (fs::is_directory(path, ec)) throw InputError(path, "is a folder, expected a file");
	std::ifstream f(path, std::ios::binary);
	if (!f) throw InputError(path, std::string("cannot open (") + std::strerror(errno) + ")");
	std::ostringstream ss;
	ss << f.rdbuf();
	return ss.str();
}

std::vector<std::string> splitFields(const std::string& line)
{
	std::vector<std::string> out;
	std::string cur;
	for (char c : line)
	{
		if (c == ' ' || c == '\t' || c == ',' || c == '\r' || c == '\n')
		{
			if (!cur.empty()) out.push_back(std::move(cur));
			cur.clear();
		}
		else
			cur.push_back(c);
	}
	if (!cur.empty()) out.push_back(std::move(cur));
	return out;
}

bool parseFiniteDouble(const std::string& s, double& out)
{
	if (s.empty()) return false;
	const char* b = s.c_str();
	char* e = nullptr;
	errno = 0;
	const double v = std::strtod(b, &e);
	if (e == b || *e != '\0' || !std::isfinite(v)) return false;
	out = v;
	return true;
}

bool isCommentOrBlank(const std::string& line)
{
	for (char c : line)
	{
		if (c == ' ' || c == '\t' || c == '\r') continue;
		return c == '#';
	}
	return true;
}

std::vector<std::string> splitLines(const std::string& text)
{
	std::vector<std::string> lines;
	std::size_t start = 0;
	while (start <= text.size())
	{
		std::size_t end = text.find('\n', start);
		if (end == std::string::npos) end = text.size();
		std::string l = text.substr(start, end - start);
		if (!l.empty() && l.back() == '\r') l.pop_back();
		lines.push_back(std::move(l));
		start = end + 1;
	}
	if (!lines.empty() && lines.back().empty()) lines.pop_back();
	return lines;
}
std::string jsonEscape(const std::string& s)
{
	std::string o;
	for (char c : s)
	{
		if (c == '"' || c == '\\')
			o += '\\', o += c;
		else if (static_cast<unsigned char>(c) < 0x20)
			o += ' ';
		else
			o += c;
	}
	return o;
}
std::string formatNumber(double v, int digits)
{
	char b[64];
	std::snprintf(b, sizeof(b), "%.*g", digits, v);
	return b;
}
}  // namespace mrpt_yesslam
