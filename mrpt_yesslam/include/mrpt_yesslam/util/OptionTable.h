#pragma once
// One table per options struct - key, member, type, range, help - from which loading, dumping, the
// key list and validation are all generated, so they cannot drift apart (before, each of the ten
// option structs had hand-written load, dump and key-list functions, and a count of -1 wrapped to
// a huge size_t). Each struct lists its options once, in `table()`, and derives from
// TTableOptions<itself> for the MRPT CLoadableOptions interface.
#include <mrpt/config/CLoadableOptions.h>

#include <cstddef>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "mrpt_yesslam/util/ConfigFile.h"

namespace mrpt_yesslam
{
/** The options of one struct, bound to its members: loads, dumps and lists them. */
class COptionTable
{
   public:
	/** One option. `set` parses and range-checks a value (throws std::invalid_argument with what
	 * was expected); `get` prints the current value; `other` is a valid value different from the
	 * current one (tests change every key with it). */
	struct TEntry
	{
		std::string key;
		TConfigKey::Type type = TConfigKey::Type::Text;
		std::string help;
		std::function<void(const std::string&)> set;
		std::function<std::string()> get;
		std::function<std::string()> other;
	};

	/** `section`: the section name printed by dump(). */
	explicit COptionTable(std::string section) : section_(std::move(section)) {}

	/** A real number in [lo, hi]. */
	COptionTable& real(const std::string& key, double& v, double lo, double hi, const std::string& help);
	/** A whole number in [lo, hi]. */
	COptionTable& integer(const std::string& key, int& v, int lo, int hi, const std::string& help);
	/** A count or size in [lo, hi]: negative values are errors, never wrapped. */
	COptionTable& count(const std::string& key, std::size_t& v, std::size_t lo, std::size_t hi,
						const std::string& help);
	/** true/false (also 1/0, yes/no). */
	COptionTable& flag(const std::string& key, bool& v, const std::string& help);
	/** Text; with `choices`, one of them. */
	COptionTable& text(const std::string& key, std::string& v, const std::string& help,
					   std::vector<std::string> choices = {});
	/** The entries of a nested options struct loaded from the same section. */
	COptionTable& append(const COptionTable& nested);

	/** Sets every option present in `section` of `c`; throws InputError("[S] key = 'v': expected
	 * ...") for a value of the wrong type or out of range. Absent keys keep their values. */
	void load(const mrpt::config::CConfigFileBase& c, const std::string& section) const;
	/** The section as INI text: a header, then per option its help as a comment and `key = value`
	 * (loadable again: config_used.ini reruns a job). */
	void dump(std::ostream& out) const;
	/** The keys with their types, for validateConfigSection. */
	std::vector<TConfigKey> keys() const;
	const std::vector<TEntry>& entries() const { return entries_; }
	const std::string& section() const { return section_; }

   private:
	std::string section_;
	std::vector<TEntry> entries_;
};

/** The CLoadableOptions interface of an options struct `Derived` that has `COptionTable table()`. */
template <class Derived>
struct TTableOptions : public mrpt::config::CLoadableOptions
{
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& section) override
	{
		static_cast<Derived*>(this)->table().load(c, section);
	}
	void dumpToTextStream(std::ostream& out) const override
	{
		Derived copy(static_cast<const Derived&>(*this));  // the table binds to members it could write
		copy.table().dump(out);
	}
	/** The keys loadFromConfigFile reads, for validateConfigSection. */
	static std::vector<TConfigKey> configKeys()
	{
		Derived d;
		return d.table().keys();
	}
};
}  // namespace mrpt_yesslam
