#pragma once
// A small command-line parser for our tools: long options only, a --help that lists every option
// with its meaning and default, and one-line errors for anything wrong (unknown option, missing
// value, non-numeric number). MRPT's bundled TCLAP prints multi-line usage on errors instead.
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace mrpt_yesslam
{
/** Declares options, parses argv into the caller's variables, prints help. */
class CommandLine
{
   public:
	/** `synopsis` is the usage line; `description` a paragraph shown by --help; `examples` lines. */
	CommandLine(std::string program, std::string synopsis, std::string description,
				std::vector<std::string> examples = {});

	/** A switch: present = true. */
	void flag(const std::string& name, const std::string& help, bool* target);
	/** A text option. */
	void text(const std::string& name, const std::string& metavar, const std::string& help, std::string* target,
			  bool required = false);
	/** A finite floating-point option. */
	void number(const std::string& name, const std::string& metavar, const std::string& help, double* target,
				bool required = false);
	/** A text option that may be given several times; each value is appended. */
	void texts(const std::string& name, const std::string& metavar, const std::string& help,
			   std::vector<std::string>* target, bool required = false);
	/** A non-negative integer option. */
	void count(const std::string& name, const std::string& metavar, const std::string& help, std::size_t* target);

	/** Parses; returns false when --help was printed (exit 0). Throws InputError for bad usage. */
	bool parse(int argc, char** argv);
	/** Whether the option appeared on the command line. */
	bool given(const std::string& name) const;
	/** The full --help text. */
	std::string help() const;

   private:
	struct Opt
	{
		std::string name, metavar, help, defaultText;
		bool takesValue = false, required = false, seen = false;
		std::function<void(const std::string&)> set;
	};
	Opt& add(const std::string& name);

	std::string program_, synopsis_, description_;
	std::vector<std::string> examples_;
	std::vector<Opt> opts_;
};

/** Runs a tool's body, turning any exception into one line "PROGRAM: error: MESSAGE" on stderr and
 * exit code 1. */
int runTool(const std::string& program, const std::function<int()>& body);

/** Installs a SIGINT/SIGTERM handler that only sets a flag, so long loops can stop cleanly and save
 * what they have; the first signal prints `stopMessage` at once (when given). With an
 * `abortMessage`, a second one asks the saving to stop after the file it is writing
 * (abortRequested; the message printed), so that what is complete stays, and a third kills the
 * process the usual way; without one, the second kills it. */
void installInterruptHandler(const char* stopMessage = nullptr, const char* abortMessage = nullptr);
/** Replaces the message a second Ctrl-C prints (a tool whose phases it affects differently). */
void setAbortMessage(const char* abortMessage);
/** True once Ctrl-C (or SIGTERM) has been received. */
bool interruptRequested();
/** True once a second Ctrl-C (or SIGTERM) has been received: stop saving after the current file. */
bool abortRequested();
/** The exit code of a run stopped by a signal, as shells report it: 128 + the first signal's
 * number (130 for Ctrl-C, 143 for SIGTERM). */
int interruptExitCode();
/** "0.1.0 (MRPT 2.5.8, OpenCV 4.6.0)": what --version prints after the program name. */
std::string versionText();
}  // namespace mrpt_yesslam
