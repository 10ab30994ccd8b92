#pragma once
// Little helpers for the versioned binary formats (map elements): fixed-size values and vectors
// written raw (every machine we build for is little-endian), and reads that throw on a short stream
// instead of leaving garbage, with a size limit so a corrupt length cannot ask for terabytes.
#include <cstdint>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace mrpt_yesslam::binio
{
/** Writes a trivially copyable value. */
template <typename T>
void put(std::ostream& o, const T& v)
{
	static_assert(std::is_trivially_copyable_v<T>);
	o.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
/** Reads a trivially copyable value; throws std::runtime_error naming `what` on a short stream. */
template <typename T>
T get(std::istream& i, const char* what)
{
	static_assert(std::is_trivially_copyable_v<T>);
	T v{};
	if (!i.read(reinterpret_cast<char*>(&v), sizeof(T))) throw std::runtime_error(std::string("truncated data reading ") + what);
	return v;
}
/** Writes a vector of trivially copyable values with its length. */
template <typename T>
void putVector(std::ostream& o, const std::vector<T>& v)
{
	put<std::uint64_t>(o, v.size());
	if (!v.empty()) o.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
}
/** Reads what putVector wrote; refuses more than `maxCount` elements (a corrupt length). */
template <typename T>
std::vector<T> getVector(std::istream& i, const char* what, std::uint64_t maxCount = 1u << 26)
{
	const auto n = get<std::uint64_t>(i, what);
	if (n > maxCount) throw std::runtime_error(std::string("implausible length reading ") + what);
	std::vector<T> v(static_cast<std::size_t>(n));
	if (n && !i.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T))))
		throw std::runtime_error(std::string("truncated data reading ") + what);
	return v;
}
/** Checks a record's version: refuses versions newer than `current` (written by a newer build). */
inline std::uint32_t getVersion(std::istream& i, const char* what, std::uint32_t current)
{
	const auto v = get<std::uint32_t>(i, what);
	if (v == 0 || v > current)
		throw std::runtime_error(std::string(what) + " has format version " + std::to_string(v) + ", this build reads up to " + std::to_string(current));
	return v;
}
}  // namespace mrpt_yesslam::binio
