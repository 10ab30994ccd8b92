#include "mrpt_yesslam/util/ConfigFile.h"

#include <algorithm>
#include <map>
#include <cctype>
#include <cmath>
#include <cstdio>

#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
std::string lowerAscii(std::string s)
{
	std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
	return s;
}

std::string trimConfigValue(const std::string& s)
{
	const auto b = s.find_first_not_of(" \t\r\n\"'");
	if (b == std::string::npos) return {};
	const auto e = s.find_last_not_of(" \t\r\n\"'");
	return s.substr(b, e - b + 1);
}

// Our YAML configs are two levels: "Section:" then indented "key: value" lines. We convert them to
// INI text ourselves because MRPT 2.5.8's CConfigFileMemory::setContentFromYAML throws on every
// nested map ("Trying to use as() on a node of type map"); the INI text then takes the same path
// as an INI file.
std::string yamlToIni(const std::string& text, const std::string& name)
{
	std::string ini;
	bool inSection = false;
	const auto lines = splitLines(text);
	for (std::size_t i = 0; i < lines.size(); i++)
	{
		std::string l = lines[i];
		// Strip comments: '#' at the start or after whitespace, outside quotes.
		char quote = 0;
		for (std::size_t k = 0; k < l.size(); k++)
		{
			if (quote)
			{
				if (l[k] == quote) quote = 0;
			}
			else if (l[k] == '"' || l[k] == '\'')
				quote = l[k];
			else if (l[k] == '#' && (k == 0 || l[k - 1] == ' ' || l[k - 1] == '\t'))
			{
				l = l.substr(0, k);
				break;
			}
		}
		const auto first = l.find_first_not_of(" \t\r");
		if (first == std::string::npos || l.compare(first, 3, "---") == 0) continue;
		const std::string where = "line " + std::to_string(i + 1) + ": ";
		const auto colon = l.find(':', first);
		if (l[first] == '-') throw InputError(name, where + "YAML lists are not used in our configs");
		if (colon == std::string::npos) throw InputError(name, where + "expected 'key: value' or 'Section:'");
		const std::string key = trimConfigValue(l.substr(first, colon - first));
		const std::string value = trimConfigValue(l.substr(colon + 1));
		if (key.empty()) throw InputError(name, where + "empty key");
		if (first == 0)
		{
			if (!value.empty())
				throw InputError(name, where + "'" + key + "' must be a section (\"" + key + ":\" then indented keys)");
			ini += "[" + key + "]\n";
			inSection = true;
		}
		else
		{
			if (!inSection) throw InputError(name, where + "indented key outside a section");
			if (value.empty())
				throw InputError(name,
								 where + "'" + key + "' has no value (nested sections are not used in our configs)");
			ini += key + " = " + value + "\n";
		}
	}
	return ini;
}

std::string stripInlineIniComments(const std::string& text)
{
	std::string out;
	for (const std::string& line : splitLines(text))
	{
		std::string l = line;
		const auto first = l.find_first_not_of(" \t");
		const bool wholeLineComment =
			first != std::string::npos && (l[first] == ';' || l[first] == '#' || l.compare(first, 2, "//") == 0);
		if (!wholeLineComment)
		{
			// A comment after a value starts at ';', '#' or "//" that follows whitespace, outside quotes.
			char quote = 0;
			for (std::size_t k = 1; k < l.size(); k++)
			{
				if (quote)
				{
					if (l[k] == quote) quote = 0;
					continue;
				}
				if (l[k] == '"' || l[k] == '\'')
				{
					quote = l[k];
					continue;
				}
				const bool afterSpace = l[k - 1] == ' ' || l[k - 1] == '\t';
				if (afterSpace && (l[k] == ';' || l[k] == '#' || l.compare(k, 2, "//") == 0))
				{
					l.erase(k);
					break;
				}
			}
			const auto e = l.find_last_not_of(" \t\r");
			l = e == std::string::npos ? std::string() : l.substr(0, e + 1);
		}
		out += l + "\n";
	}
	return out;
}

std::vector<std::string> iniStructureWarnings(const std::string& text, const std::string& name)
{
	std::vector<std::string> w;
	bool inSection = false;
	std::string section;
	std::map<std::string, std::size_t> seen;  // "section\nkey" (lower case) -> line
	const auto lines = splitLines(stripInlineIniComments(text));
	for (std::size_t i = 0; i < lines.size(); i++)
	{
		const std::string l = trimConfigValue(lines[i]);
		if (l.empty() || l[0] == ';' || l[0] == '#' || l.compare(0, 2, "//") == 0) continue;
		const std::string where = name + ":" + std::to_string(i + 1) + ": ";
		if (l[0] == '[')
		{
			if (l.back() != ']')
				w.push_back(where + "section line '" + l + "' has no closing ']': its keys are ignored");
			section = lowerAscii(l.back() == ']' ? l.substr(1, l.size() - 2) : l.substr(1));
			inSection = true;
		}
		else if (!inSection)
			w.push_back(where + "'" + l + "' comes before any [Section]: ignored");
		else if (const auto eq = l.find('='); eq != std::string::npos)
		{
			// MRPT takes the last of two values silently: a key set twice is usually an edit gone wrong.
			const std::string key = trimConfigValue(l.substr(0, eq));
			const auto [it, fresh] = seen.emplace(section + "\n" + lowerAscii(key), i + 1);
			if (!fresh)
				w.push_back(where + "'" + key + "' is set again (first on line " + std::to_string(it->second) +
							"): the last value is used");
		}
	}
	return w;
}

std::unique_ptr<mrpt::config::CConfigFileMemory> parseConfigText(const std::string& text, bool yaml,
																 const std::string& name)
{
	auto cfg = std::make_unique<mrpt::config::CConfigFileMemory>();
	try
	{
		cfg->setContent(yaml ? yamlToIni(text, name) : stripInlineIniComments(text));
	}
	catch (const InputError&)
	{
		throw;
	}
	catch (const std::exception& e)
	{
		const std::string why = exceptionSummary(e.what());
		throw InputError(name, std::string("not a valid ") + (yaml ? "YAML" : "INI") + " config (" + why + ")");
	}
	return cfg;
}

std::unique_ptr<mrpt::config::CConfigFileMemory> loadConfigFile(const std::string& path,
																std::vector<std::string>* warnings)
{
	const std::string text = readTextFile(path);
	const std::string l = lowerAscii(path);
	const bool yaml =
		(l.size() > 5 && l.substr(l.size() - 5) == ".yaml") || (l.size() > 4 && l.substr(l.size() - 4) == ".yml");
	if (warnings && !yaml)
		for (auto& w : iniStructureWarnings(text, path)) warnings->push_back(std::move(w));
	return parseConfigText(text, yaml, path);
}

std::vector<std::string> validateConfigSection(const mrpt::config::CConfigFileBase& cfg, const std::string& file,
											   const std::string& section, const std::vector<TConfigKey>& keys)
{
	std::vector<std::string> warnings;
	if (!cfg.sectionExists(section)) return warnings;
	std::vector<std::string> present;
	cfg.getAllKeys(section, present);
	std::string known;
	for (const auto& k : keys) known += (known.empty() ? "" : ", ") + k.name;
	for (const auto& key : present)
	{
		const auto it = std::find_if(keys.begin(), keys.end(),
									 [&](const TConfigKey& k) { return lowerAscii(k.name) == lowerAscii(key); });
		if (it == keys.end())
		{
			warnings.push_back(file + ": [" + section + "] unknown key '" + key + "' ignored (known: " + known + ")");
			continue;
		}
		const std::string v = trimConfigValue(cfg.read_string(section, key, ""));
		const std::string where = "[" + section + "] " + key + " = '" + v + "': ";
		double d = 0;
		switch (it->type)
		{
			case TConfigKey::Type::Number:
				if (!parseFiniteDouble(v, d)) throw InputError(file, where + "expected a number");
				break;
			case TConfigKey::Type::Integer:
				if (!parseFiniteDouble(v, d) || d != std::floor(d) || std::abs(d) > 2e9)
					throw InputError(file, where + "expected a whole number");
				break;
			case TConfigKey::Type::Boolean:
			{
				const std::string b = lowerAscii(v);
				if (b != "true" && b != "false" && b != "1" && b != "0" && b != "yes" && b != "no")
					throw InputError(file, where + "expected true or false");
				break;
			}
			case TConfigKey::Type::Text: break;
		}
	}
	return warnings;
}

void loadOptionsFromFile(const std::string& path, const std::string& section, mrpt::config::CLoadableOptions& opts,
						 const std::vector<TConfigKey>& keys)
{
	const auto cfg = loadConfigFile(path);
	loadOptions(*cfg, path, section, opts, keys);
}

void loadOptions(const mrpt::config::CConfigFileBase& cfg, const std::string& path, const std::string& section,
				 mrpt::config::CLoadableOptions& opts, const std::vector<TConfigKey>& keys)
{
	for (const auto& w : validateConfigSection(cfg, path, section, keys)) printWarning(w);
	try
	{
		opts.loadFromConfigFile(cfg, section);
	}
	catch (const InputError& e)
	{
		throw InputError(path, e.what());
	}
	catch (const std::exception& e)
	{
		throw InputError(path, "[" + section + "] cannot be loaded (" + exceptionSummary(e.what()) + ")");
	}
}
}  // namespace mrpt_yesslam
