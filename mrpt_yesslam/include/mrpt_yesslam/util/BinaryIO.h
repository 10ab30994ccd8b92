#pragma once
// Little helpers for the versioned binary formats (map elements): fixed-size values and vectors
// written raw (every machine we build for is little-endian), and reads that throw on a short stream
// instead of leaving garbage, with a size limit so a corrupt length cannot ask for terabytes.
#include <cstdint>
#include <cstring>
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
	if (!i.read(reinterpret_cast<char*>(&v), sizeof(T)))
		throw std::runtime_error(std::string("truncated data reading ") + what);
	return v;
}
/** Writes a vector of trivially copyable values with its length. */
template <typename T>
void putVector(std::ostream& o, const std::vector<T>& v)
{
	put<std::uint64_t>(o, v.size());
	if (!v.empty())
		o.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
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
/** FNV-1a's xor-multiply on 64-bit words (then the tail bytes): detects a damaged or truncated file
 * before its contents are trusted, at a fraction of a millisecond for 5 MB (byte by byte it took
 * most of a vocabulary's 40 ms load). */
inline std::uint64_t checksum(const char* p, std::size_t n)
{
	std::uint64_t h = 1469598103934665603ull;
	std::size_t i = 0;
	for (; i + 8 <= n; i += 8)
	{
		std::uint64_t w;
		std::memcpy(&w, p + i, 8);
		h = (h ^ w) * 1099511628211ull;
		h ^= h >> 29;
	}
	for (; i < n; i++) h = (h ^ static_cast<std::uint8_t>(p[i])) * 1099511628211ull;
	return h;
}
/** Checks a record's version: refuses versions newer than `current` (written by a newer build). */
inline std::uint32_t getVersion(std::istream& i, const char* what, std::uint32_t current)
{
	const auto v = get<std::uint32_t>(i, what);
	if (v == 0 || v > current)
		throw std::runtime_error(std::string(what) + " has format version " + std::to_string(v) +
								 ", this build reads up to " + std::to_string(current));
	return v;
}
}  // namespace mrpt_yesslam::binio
