#include "mrpt_yesslam/util/OptionTable.h"

#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
namespace
{
template <class T>
std::string str(const T& v)
{
	std::ostringstream o;
	o.precision(10);
	o << v;
	return o.str();
}

std::string rangeText(const std::string& lo, const std::string& hi, bool unbounded)
{
	return unbounded ? ">= " + lo : "in [" + lo + ", " + hi + "]";
}

/** A whole number in [lo, hi] parsed from `s`, or std::invalid_argument saying what was expected. */
long double parseWhole(const std::string& s, long double lo, long double hi, const std::string& range)
{
	double d = 0;
	if (!parseFiniteDouble(s, d) || d != std::floor(d) || d < lo || d > hi)
		throw std::invalid_argument("expected a whole number " + range);
	return d;
}
}  // namespace

COptionTable& COptionTable::real(const std::string& key, double& v, double lo, double hi, const std::string& help)
{
	const bool open = hi == std::numeric_limits<double>::max();
	const std::string range = rangeText(str(lo), str(hi), open);
	entries_.push_back({key, TConfigKey::Type::Number, help,
						[&v, lo, hi, range](const std::string& s)
						{
							double d = 0;
							if (!parseFiniteDouble(s, d) || d < lo || d > hi)
								throw std::invalid_argument("expected a number " + range);
							v = d;
						},
						[&v] { return str(v); },
						[&v, lo, hi]
						{
							const double up = v + std::max(0.5 * std::abs(v), 0.01);
							return str(up <= hi ? up : (lo + v) / 2);
						}});
	return *this;
}

COptionTable& COptionTable::integer(const std::string& key, int& v, int lo, int hi, const std::string& help)
{
	const std::string range = rangeText(str(lo), str(hi), hi == std::numeric_limits<int>::max());
	entries_.push_back({key, TConfigKey::Type::Integer, help,
						[&v, lo, hi, range](const std::string& s)
						{ v = static_cast<int>(parseWhole(s, lo, hi, range)); },
						[&v] { return str(v); }, [&v, lo, hi] { return str(v < hi ? v + 1 : lo); }});
	return *this;
}

COptionTable& COptionTable::count(const std::string& key, std::size_t& v, std::size_t lo, std::size_t hi,
								  const std::string& help)
{
	const std::string range = rangeText(str(lo), str(hi), hi == std::numeric_limits<std::size_t>::max());
	entries_.push_back({key, TConfigKey::Type::Integer, help,
						[&v, lo, hi, range](const std::string& s) {
							v = static_cast<std::size_t>(
								parseWhole(s, static_cast<long double>(lo), std::min<long double>(hi, 1e15), range));
						},
						[&v] { return str(v); }, [&v, lo, hi] { return str(v < hi ? v + 1 : lo); }});
	return *this;
}

COptionTable& COptionTable::flag(const std::string& key, bool& v, const std::string& help)
{
	entries_.push_back({key, TConfigKey::Type::Boolean, help,
						[&v](const std::string& s)
						{
							const std::string b = lowerAscii(s);
							if (b == "true" || b == "1" || b == "yes")
								v = true;
							else if (b == "false" || b == "0" || b == "no")
								v = false;
							else
								throw std::invalid_argument("expected true or false");
						},
						[&v] { return std::string(v ? "true" : "false"); },
						[&v] { return std::string(v ? "false" : "true"); }});
	return *this;
}

COptionTable& COptionTable::text(const std::string& key, std::string& v, const std::string& help,
								 std::vector<std::string> choices)
{
	std::string list;
	for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
	entries_.push_back({key, TConfigKey::Type::Text, choices.empty() ? help : help + " (" + list + ")",
						[&v, choices, list](const std::string& s)
						{
							if (!choices.empty() && std::find(choices.begin(), choices.end(), s) == choices.end())
								throw std::invalid_argument("expected one of " + list);
							v = s;
						},
						[&v] { return v; },
						[&v, choices]
						{
							for (const auto& c : choices)
								if (c != v) return c;
							return v + "x";
						}});
	return *this;
}

COptionTable& COptionTable::append(const COptionTable& nested)
{
	entries_.insert(entries_.end(), nested.entries_.begin(), nested.entries_.end());
	return *this;
}

void COptionTable::load(const mrpt::config::CConfigFileBase& c, const std::string& section) const
{
	if (!c.sectionExists(section)) return;
	std::vector<std::string> present;
	c.getAllKeys(section, present);
	for (const TEntry& e : entries_)
	{
		// Keys match case-insensitively, as validateConfigSection and MRPT's INI reader.
		const auto it = std::find_if(present.begin(), present.end(),
									 [&](const std::string& k) { return lowerAscii(k) == lowerAscii(e.key); });
		if (it == present.end()) continue;
		const std::string v = trimConfigValue(c.read_string(section, *it, ""));
		try
		{
			e.set(v);
		}
		catch (const std::invalid_argument& ex)
		{
			throw InputError("", "[" + section + "] " + e.key + " = '" + v + "': " + ex.what());
		}
	}
}

void COptionTable::dump(std::ostream& out) const
{
	out << "[" << section_ << "]\n";
	for (const TEntry& e : entries_)
	{
		if (!e.help.empty()) out << "; " << e.help << "\n";
		out << e.key << " = " << e.get() << "\n";
	}
}

std::vector<TConfigKey> COptionTable::keys() const
{
	std::vector<TConfigKey> k;
	for (const TEntry& e : entries_) k.push_back({e.key, e.type});
	return k;
}
}  // namespace mrpt_yesslam
