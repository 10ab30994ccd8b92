#pragma once
// Small strict parsers shared by every reader of user text files, so that they all reject the
// same malformed input with the same kind of message.
#include <string>
#include <vector>

namespace mrpt_yesslam
{
/** Reads a whole file; throws InputError("PATH: cannot open ...") if it cannot. */
std::string readTextFile(const std::string& path);

/** Splits a line on spaces, tabs and commas (the TUM tools accept all three). */
std::vector<std::string> splitFields(const std::string& line);

/** Parses a finite double; returns false for anything else (trailing garbage, nan, inf, empty). */
bool parseFiniteDouble(const std::string& s, double& out);

/** True for lines the TUM readers skip: empty, whitespace only, or starting with '#'. */
bool isCommentOrBlank(const std::string& line);

/** `s` as the inside of a JSON string: quotes and backslashes escaped, control characters as spaces. */
std::string jsonEscape(const std::string& s);

/** Splits text into lines (handles \n and \r\n). */
std::vector<std::string> splitLines(const std::string& text);

/** `v`, or 0 where it would print as a zero with 9 decimals: no "-0.000000000" in files. */
inline double withoutNegativeZero(double v)
{
	return v < 5e-10 && v > -5e-10 ? 0.0 : v;
}

/** "1 keyframe", "2 keyframes": a count with its noun (plural by adding s). */
inline std::string countOf(std::size_t n, const std::string& noun)
{
	return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

/** A number for messages: %g with `digits` significant digits ("0.005", "4", "6.12"). */
std::string formatNumber(double v, int digits = 3);
}  // namespace mrpt_yesslam
