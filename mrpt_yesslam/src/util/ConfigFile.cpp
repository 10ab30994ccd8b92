#include "mrpt_yesslam/util/ConfigFile.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "mrpt_yesslam/io/TextParsing.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
namespace
{
std::string lower(std::string s)
{
	std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
	return s;
}

std::string trim(const std::string& s)
{
	const auto b = s.find_first_not_of(" \t\r\n\"'");
	if (b == std::string::npos) return {};
	const auto e = s.find_last_not_of(" \t\r\n\"'");
	return s.substr(b, e - b + 1);
}
}  // namespace

std::unique_ptr<mrpt::config::CConfigFileMemory> parseConfigText(
	const std::string& text, bool yaml, const std::string& name)
{
	auto cfg = std::make_unique<mrpt::config::CConfigFileMemory>();
	try
	{
		if (yaml)
			cfg->setContentFromYAML(text);
		else
			cfg->setContent(text);
	}
	catch (const std::exception& e)
	{
		std::string why = e.what();
		why = why.substr(0, why.find('\n'));
		throw InputError(name, std::string("not a valid ") + (yaml ? "YAML" : "INI") + " config (" + why + ")");
	}
	return cfg;
}

std::unique_ptr<mrpt::config::CConfigFileMemory> loadConfigFile(const std::string& path)
{
	const std::string text = readTextFile(path);
	const std::string l = lower(path);
	const bool yaml = (l.size() > 5 && l.substr(l.size() - 5) == ".yaml") || (l.size() > 4 && l.substr(l.size() - 4) == ".yml");
	return parseConfigText(text, yaml, path);
}

std::vector<std::string> validateConfigSection(
	const mrpt::config::CConfigFileBase& cfg, const std::string& file, const std::string& section,
	const std::vector<TConfigKey>& keys)
{
	std::vector<std::string> warnings;
	if (!cfg.sectionExists(section)) return warnings;
	std::vector<std::string> present;
	cfg.getAllKeys(section, present);
	std::string known;
	for (const auto& k : keys) known += (known.empty() ? "" : ", ") + k.name;
	for (const auto& key : present)
	{
		const auto it = std::find_if(keys.begin(), keys.end(), [&](const TConfigKey& k) { return lower(k.name) == lower(key); });
		if (it == keys.end())
		{
			warnings.push_back(file + ": [" + section + "] unknown key '" + key + "' ignored (known: " + known + ")");
			continue;
		}
		const std::string v = trim(cfg.read_string(section, key, ""));
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
				const std::string b = lower(v);
				if (b != "true" && b != "false" && b != "1" && b != "0" && b != "yes" && b != "no")
					throw InputError(file, where + "expected true or false");
				break;
			}
			case TConfigKey::Type::Text:
				break;
		}
	}
	return warnings;
}
}  // namespace mrpt_yesslam
