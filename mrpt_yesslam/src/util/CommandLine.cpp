#include "mrpt_yesslam/util/CommandLine.h"

#include <unistd.h>

#include <mrpt/version.h>

#include <atomic>
#include <opencv2/core/version.hpp>
#include <csignal>
#include <cstdio>
#include <sstream>

#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
CommandLine::CommandLine(std::string program, std::string synopsis, std::string description,
						 std::vector<std::string> examples)
	: program_(std::move(program)),
	  synopsis_(std::move(synopsis)),
	  description_(std::move(description)),
	  examples_(std::move(examples))
{
}

CommandLine::Opt& CommandLine::add(const std::string& name)
{
	opts_.push_back({});
	opts_.back().name = name;
	return opts_.back();
}

void CommandLine::flag(const std::string& name, const std::string& help, bool* target)
{
	Opt& o = add(name);
	o.help = help;
	o.set = [target](const std::string&) { *target = true; };
}

void CommandLine::text(const std::string& name, const std::string& metavar, const std::string& help,
					   std::string* target, bool required)
{
	Opt& o = add(name);
	o.metavar = metavar;
	o.help = help;
	o.takesValue = true;
	o.required = required;
	if (!target->empty()) o.defaultText = *target;
	o.set = [target](const std::string& v) { *target = v; };
}

void CommandLine::texts(const std::string& name, const std::string& metavar, const std::string& help,
						std::vector<std::string>* target, bool required)
{
	Opt& o = add(name);
	o.metavar = metavar;
	o.help = help + " (repeatable)";
	o.takesValue = true;
	o.required = required;
	o.set = [target](const std::string& v) { target->push_back(v); };
}

void CommandLine::number(const std::string& name, const std::string& metavar, const std::string& help, double* target,
						 bool required)
{
	Opt& o = add(name);
	o.metavar = metavar;
	o.help = help;
	o.takesValue = true;
	o.required = required;
	if (!required)
	{
		std::ostringstream ss;
		ss << *target;
		o.defaultText = ss.str();
	}
	o.set = [target, name](const std::string& v)
	{
		if (!parseFiniteDouble(v, *target)) throw InputError("", "--" + name + " expects a number, got '" + v + "'");
	};
}

void CommandLine::count(const std::string& name, const std::string& metavar, const std::string& help,
						std::size_t* target)
{
	Opt& o = add(name);
	o.metavar = metavar;
	o.help = help;
	o.takesValue = true;
	o.defaultText = std::to_string(*target);
	o.set = [target, name](const std::string& v)
	{
		double d;
		if (!parseFiniteDouble(v, d) || d < 0 || d != static_cast<double>(static_cast<long long>(d)) || d > 1e15)
			throw InputError("", "--" + name + " expects a non-negative integer, got '" + v + "'");
		*target = static_cast<std::size_t>(d);
	};
}

bool CommandLine::parse(int argc, char** argv)
{
	for (int i = 1; i < argc; i++)
	{
		std::string a = argv[i];
		if (a == "-h" || a == "--help")
		{
			std::fputs(help().c_str(), stdout);
			return false;
		}
		if (a == "--version")
		{
			std::printf("%s %s\n", program_.c_str(), versionText().c_str());
			return false;
		}
		if (a.rfind("--", 0) != 0)
			throw InputError("", "unexpected argument '" + a + "' (options start with --; see --help)");
		std::string name = a.substr(2), value;
		bool inlineValue = false;
		if (const auto eq = name.find('='); eq != std::string::npos)
		{
			value = name.substr(eq + 1);
			name = name.substr(0, eq);
			inlineValue = true;
		}
		Opt* o = nullptr;
		for (auto& c : opts_)
			if (c.name == name) o = &c;
		// Our tools name their output --out or --output (tum2rawlog and yesslam-oni write one file,
		// the others a folder or a picture): each takes the other spelling too, so a user's habit
		// from one tool works in all of them.
		if (!o && (name == "out" || name == "output"))
			for (auto& c : opts_)
				if (c.name == (name == "out" ? "output" : "out")) o = &c;
		if (!o) throw InputError("", "unknown option --" + name + " (see --help)");
		if (o->takesValue && !inlineValue)
		{
			// "--input --out x": the next word is another option, not the value the user forgot.
			const bool nextIsOption =
				i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) == 0 && std::string(argv[i + 1]).size() > 2;
			if (i + 1 >= argc || nextIsOption)
				throw InputError("", "option --" + name + " needs a value " + o->metavar);
			value = argv[++i];
		}
		if (!o->takesValue && inlineValue) throw InputError("", "option --" + name + " takes no value");
		o->set(value);
		o->seen = true;
	}
	for (const auto& o : opts_)
		if (o.required && !o.seen) throw InputError("", "missing required option --" + o.name + " (see --help)");
	return true;
}

bool CommandLine::given(const std::string& name) const
{
	for (const auto& o : opts_)
		if (o.name == name) return o.seen;
	return false;
}

std::string CommandLine::help() const
{
	std::string h = "Usage: " + synopsis_ + "\n\n" + description_ + "\n\nOptions:\n";
	for (const auto& o : opts_)
	{
		std::string left = "  --" + o.name + (o.takesValue ? " " + o.metavar : "");
		if (left.size() < 26)
			left += std::string(26 - left.size(), ' ');
		else
			left += "\n" + std::string(26, ' ');
		std::string text = o.help;
		if (o.required) text += " (required)";
		// A help text that states its own default (a computed one) keeps it alone.
		if (!o.defaultText.empty() && o.help.find("[default:") == std::string::npos)
			text += " [default: " + o.defaultText + "]";
		h += left + text + "\n";
	}
	h += "  --help                  Show this help and exit.\n";
	h += "  --version               Show the version (and the MRPT and OpenCV it was built with) and exit.\n";
	if (!examples_.empty())
	{
		h += "\nExamples:\n";
		for (const auto& e : examples_) h += "  " + e + "\n";
	}
	return h;
}

namespace
{
std::atomic<int> g_interrupts{0};
std::atomic<int> g_firstSignal{0};
const char* g_stopMessage = nullptr;
std::atomic<const char*> g_abortMessage{nullptr};  // the handler may read it while a tool changes it
void writeStderr(const char* m)
{
	if (!m) return;
	std::size_t n = 0;
	while (m[n]) n++;
	const ssize_t ignored = ::write(2, m, n);  // async-signal-safe, unlike stdio
	(void)ignored;
}
extern "C" void onSignal(int sig)
{
	int none = 0;
	g_firstSignal.compare_exchange_strong(none, sig);
	const int before = g_interrupts.fetch_add(1);
	if (before == 0)
		writeStderr(g_stopMessage);
	else if (const char* abort = g_abortMessage.load();
			 before == 1 && abort)  // a tool that can stop saving early said so
		writeStderr(abort);
	else
	{
		std::signal(sig, SIG_DFL);
		std::raise(sig);
	}
}
}  // namespace

void installInterruptHandler(const char* stopMessage, const char* abortMessage)
{
	g_stopMessage = stopMessage;
	g_abortMessage = abortMessage;
	std::signal(SIGINT, onSignal);
	std::signal(SIGTERM, onSignal);
}

void setAbortMessage(const char* abortMessage)
{
	g_abortMessage = abortMessage;
}

bool interruptRequested()
{
	return g_interrupts.load() > 0;
}

bool abortRequested()
{
	return g_interrupts.load() > 1;
}

int interruptExitCode()
{
	const int sig = g_firstSignal.load();
	return 128 + (sig > 0 ? sig : SIGINT);
}

std::string versionText()
{
	char buf[160];
	std::snprintf(buf, sizeof(buf), "%s (MRPT %d.%d.%d, OpenCV %s)", YESSLAM_VERSION, (MRPT_VERSION >> 8) & 0xf,
				  (MRPT_VERSION >> 4) & 0xf, MRPT_VERSION & 0xf, CV_VERSION);
	return buf;
}

int runTool(const std::string& program, const std::function<int()>& body)
{
	auto oneLine = [](std::string s)
	{
		const auto p = s.find('\n');
		if (p != std::string::npos) s = s.substr(0, p);
		return s;
	};
	setProgramName(program);
	try
	{
		return body();
	}
	catch (const InputError& e)
	{
		std::fprintf(stderr, "%s: error: %s\n", program.c_str(), oneLine(e.what()).c_str());
		return 1;
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "%s: error: %s\n", program.c_str(), oneLine(e.what()).c_str());
		return 1;
	}
	catch (...)
	{
		std::fprintf(stderr, "%s: error: unknown failure\n", program.c_str());
		return 1;
	}
}
}  // namespace mrpt_yesslam
