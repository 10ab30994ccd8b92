#pragma once
// The one exception type of the project: main() catches it and prints its message as one line.
#include <stdexcept>
#include <string>

namespace mrpt_yesslam
{
/** An error caused by user input (a file, an option): the message names the file and what is wrong. */
class InputError : public std::runtime_error
{
   public:
	/** Builds "FILE: PROBLEM"; an empty file gives just the problem. */
	InputError(const std::string& file, const std::string& problem)
		: std::runtime_error(file.empty() ? problem : file + ": " + problem)
	{
	}
};
/** One line that says what went wrong in a third-party exception message: MRPT's multi-line
 * messages ("==== MRPT exception ====", "Message: ...", a call stack) give their Message line. */
std::string exceptionSummary(const std::string& what);

/** Prints "PROGRAM: warning: MESSAGE" on stderr, one line (newlines in the message become "; "):
 * PROGRAM is the tool runTool runs ("mrpt_yesslam" in programs that do not use it). */
void printWarning(const std::string& message);
/** The name printWarning uses (runTool sets it). */
void setProgramName(const std::string& name);
}  // namespace mrpt_yesslam
