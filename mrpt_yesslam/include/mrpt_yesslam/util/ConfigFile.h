#pragma once
// Loading configuration files (INI, or YAML through MRPT's own converter, so both formats share one
// code path into the TOptions structs) and checking them: a misspelt key is a warning, a value of
// the wrong type is an error naming the file, section and key. MRPT_LOAD_CONFIG_VAR alone would
// silently read "abc" as 0.
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/config/CLoadableOptions.h>

#include <memory>
#include <string>
#include <vector>

namespace mrpt_yesslam
{
/** One key a TOptions struct reads, with the type its value must have. */
struct TConfigKey
{
	enum class Type
	{
		Number,   //!< finite floating point
		Integer,  //!< whole number
		Boolean,  //!< true/false, 1/0, yes/no
		Text      //!< anything
	};
	std::string name;
	Type type = Type::Text;
};

/** `s` in lower case (ASCII): config keys match case-insensitively. */
std::string lowerAscii(std::string s);
/** A config value without surrounding whitespace and quotes. */
std::string trimConfigValue(const std::string& s);

/** INI text with comments after values removed ("maxDiff = 0.02  ; pairing window"): ';', '#' or
 * "//" after whitespace, outside quotes, as MRPT's own INI files write them. */
std::string stripInlineIniComments(const std::string& text);
/** One warning per INI line MRPT would silently ignore: a section line without its closing ']',
 * a key before any section ("FILE:LINE: ..."). */
std::vector<std::string> iniStructureWarnings(const std::string& text, const std::string& nameForErrors);

/** Parses config text: YAML when `yaml` is true, INI otherwise (comments after values removed). Throws InputError(name,
 * ...) for text MRPT cannot parse. */
std::unique_ptr<mrpt::config::CConfigFileMemory> parseConfigText(const std::string& text, bool yaml,
																 const std::string& nameForErrors);

/** Loads a config file; ".yaml"/".yml" files are YAML, anything else INI. With `warnings`, an INI
 * file's lines MRPT would ignore are added to it (iniStructureWarnings; the file is read once). */
std::unique_ptr<mrpt::config::CConfigFileMemory> loadConfigFile(const std::string& path,
																std::vector<std::string>* warnings = nullptr);

/** Checks one section against the keys its TOptions reads. Returns one warning per unknown key
 * ("FILE: [Section] unknown key 'maxdif' (known: ...)"); throws InputError for a value of the wrong
 * type. A missing section is fine (defaults apply). */
std::vector<std::string> validateConfigSection(const mrpt::config::CConfigFileBase& cfg, const std::string& fileName,
											   const std::string& section, const std::vector<TConfigKey>& keys);
/** Loads `path`, validates `section` against `keys` (warnings go to stderr, one line each) and
 * fills `opts` from it; throws InputError for an unreadable file or a value of the wrong type. */
void loadOptionsFromFile(const std::string& path, const std::string& section, mrpt::config::CLoadableOptions& opts,
						 const std::vector<TConfigKey>& keys);
/** The same for a file parsed already (`path` names it in messages): one parse for many sections. */
void loadOptions(const mrpt::config::CConfigFileBase& cfg, const std::string& path, const std::string& section,
				 mrpt::config::CLoadableOptions& opts, const std::vector<TConfigKey>& keys);
}  // namespace mrpt_yesslam
