#include "mrpt_yesslam/io/PngDecoder.h"

#include <libdeflate.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "../util/Deflate.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
namespace
{
std::uint32_t bigEndian32(const std::uint8_t* p)
{
	return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) | std::uint32_t(p[3]);
}

int paeth(int a, int b, int c)
{
	const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
	return (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
}

// The Sub filter undone for BPP bytes a pixel: each byte plus the one a pixel before it.
template <std::size_t BPP>
void subRow(std::uint8_t* row, std::size_t n)
{
	std::uint8_t left[BPP];
	for (std::size_t b = 0; b < BPP; b++) left[b] = row[b];
	for (std::size_t i = BPP; i + BPP <= n; i += BPP)
		for (std::size_t b = 0; b < BPP; b++) row[i + b] = left[b] = static_cast<std::uint8_t>(row[i + b] + left[b]);
}

// Undoes one row's filter (PNG specification, section 9) in place; prev is the row above, already
// unfiltered (zeros for the first row). False for an unknown filter type.
bool unfilterRow(std::uint8_t type, std::uint8_t* row, const std::uint8_t* prev, std::size_t n, std::size_t bpp)
{
	switch (type)
	{
		case 0: return true;
		case 1:
			// Every row of the TUM and Bonn frames is Sub-filtered: the running sums stay in registers
			// (through memory, each byte would wait for the store before it).
			if (bpp == 3)
				subRow<3>(row, n);
			else if (bpp == 2)
				subRow<2>(row, n);
			else
				for (std::size_t i = bpp; i < n; i++) row[i] = static_cast<std::uint8_t>(row[i] + row[i - bpp]);
			return true;
		case 2:
			for (std::size_t i = 0; i < n; i++) row[i] = static_cast<std::uint8_t>(row[i] + prev[i]);
			return true;
		case 3:
			for (std::size_t i = 0; i < bpp; i++) row[i] = static_cast<std::uint8_t>(row[i] + (prev[i] >> 1));
			for (std::size_t i = bpp; i < n; i++)
				row[i] = static_cast<std::uint8_t>(row[i] + ((row[i - bpp] + prev[i]) >> 1));
			return true;
		case 4:
			for (std::size_t i = 0; i < bpp; i++) row[i] = static_cast<std::uint8_t>(row[i] + prev[i]);
			for (std::size_t i = bpp; i < n; i++)
				row[i] = static_cast<std::uint8_t>(row[i] + paeth(row[i - bpp], prev[i], prev[i - bpp]));
			return true;
		default: return false;
	}
}

TPngDecodeResult damaged(const std::string& why)
{
	TPngDecodeResult r;
	r.handled = true;
	r.error = why;
	return r;
}
}  // namespace

TPngDecodeResult decodePng(const std::uint8_t* data, std::size_t size, int imreadFlags)
{
	static const std::uint8_t signature[8] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
	TPngDecodeResult notHere;
	if (size < 8 + 25 || std::memcmp(data, signature, 8) != 0) return notHere;
	// IHDR comes first (the specification requires it; libpng refuses a file without).
	const std::uint8_t* ihdr = data + 8;
	if (bigEndian32(ihdr) != 13 || std::memcmp(ihdr + 4, "IHDR", 4) != 0) return notHere;
	const std::uint32_t width = bigEndian32(ihdr + 8), height = bigEndian32(ihdr + 12);
	const int bitDepth = ihdr[16], colourType = ihdr[17], compression = ihdr[18], filter = ihdr[19],
			  interlace = ihdr[20];
	// The kinds RGB-D datasets store, as OpenCV's decoder gives them for these flags (it also
	// turns grey into BGR for IMREAD_COLOR and 16 bits into 8: left to it).
	int type = -1;
	if (colourType == 2 && bitDepth == 8 && (imreadFlags == cv::IMREAD_COLOR || imreadFlags == cv::IMREAD_UNCHANGED))
		type = CV_8UC3;
	if (colourType == 0 && bitDepth == 8 && imreadFlags == cv::IMREAD_UNCHANGED) type = CV_8UC1;
	if (colourType == 0 && bitDepth == 16 && imreadFlags == cv::IMREAD_UNCHANGED) type = CV_16UC1;
	// libpng refuses sides over a million pixels: left to it (and its message).
	if (type < 0 || compression != 0 || filter != 0 || interlace != 0 || width == 0 || height == 0 || width > 1000000 ||
		height > 1000000)
		return notHere;
	const std::size_t channels = type == CV_8UC3 ? 3 : 1,
					  bytesPerPixel = channels * static_cast<std::size_t>(bitDepth / 8);
	const std::size_t rowBytes = static_cast<std::size_t>(width) * bytesPerPixel;
	// A header claiming more than 1 GiB of pixels is left to OpenCV's limits and messages.
	if (rowBytes > (std::size_t(1) << 30) / height) return notHere;
	if (libdeflate_crc32(0, ihdr + 4, 4 + 13) != bigEndian32(ihdr + 8 + 13)) return damaged("CRC error in IHDR");

	// The consecutive IDAT chunks' data are one zlib stream. Ancillary chunks (text, gamma, physical
	// size) change nothing OpenCV gives, except tRNS (transparency) and eXIf (OpenCV turns the image
	// by its orientation): left to OpenCV, as are unknown critical chunks and IDATs split by another
	// chunk (libpng refuses both).
	thread_local std::vector<std::uint8_t> stream;  // kept: a reader decodes frame after frame
	stream.clear();
	bool ended = false, seenIdat = false, idatDone = false;
	for (std::size_t at = 8 + 25; at + 12 <= size;)
	{
		const std::uint32_t length = bigEndian32(data + at);
		const std::uint8_t* chunkType = data + at + 4;
		if (length > size - at - 12) return damaged("a chunk runs past the end of the file");
		const bool idat = std::memcmp(chunkType, "IDAT", 4) == 0, iend = std::memcmp(chunkType, "IEND", 4) == 0;
		const bool critical = chunkType[0] >= 'A' && chunkType[0] <= 'Z';
		if (std::memcmp(chunkType, "tRNS", 4) == 0 || std::memcmp(chunkType, "eXIf", 4) == 0 ||
			(critical && !idat && !iend))
			return notHere;
		if (!idat && seenIdat) idatDone = true;
		if (idat)
		{
			if (idatDone) return notHere;
			seenIdat = true;
			if (libdeflate_crc32(0, chunkType, 4 + length) != bigEndian32(chunkType + 4 + length))
				return damaged("CRC error in IDAT");
			stream.insert(stream.end(), chunkType + 4, chunkType + 4 + length);
		}
		if (iend)
		{
			ended = true;
			break;
		}
		at += 12 + length;
	}
	if (!ended) return damaged("truncated PNG: no IEND chunk");
	if (stream.empty()) return damaged("no IDAT chunk");

	const std::size_t stride = rowBytes + 1;  // each row starts with its filter type
	thread_local std::vector<std::uint8_t> raw;
	// The buffers are kept for the next frame (a reader decodes frame after frame), but not those of
	// a huge image, whatever the outcome.
	struct Release
	{
		~Release()
		{
			if (raw.capacity() > (std::size_t(64) << 20)) std::vector<std::uint8_t>().swap(raw);
			if (stream.capacity() > (std::size_t(64) << 20)) std::vector<std::uint8_t>().swap(stream);
		}
	} release;
	raw.resize(stride * height);
	libdeflate_decompressor* d = threadDecompressor();  // the reader thread decodes; tests may decode from several
	if (!d) return notHere;                             // out of memory: OpenCV may still manage
	const libdeflate_result z =
		libdeflate_zlib_decompress(d, stream.data(), stream.size(), raw.data(), raw.size(), nullptr);
	// More data than the image needs: libpng only warns and decodes it, so OpenCV does.
	if (z == LIBDEFLATE_INSUFFICIENT_SPACE) return notHere;
	if (z != LIBDEFLATE_SUCCESS) return damaged("the compressed image data is corrupt or too short");
	const std::vector<std::uint8_t> zeros(rowBytes, 0);
	for (std::size_t y = 0; y < height; y++)
	{
		std::uint8_t* row = raw.data() + y * stride;
		const std::uint8_t* prev = y ? raw.data() + (y - 1) * stride + 1 : zeros.data();
		if (!unfilterRow(row[0], row + 1, prev, rowBytes, bytesPerPixel))
			return damaged("unknown row filter type " + std::to_string(row[0]));
	}

	TPngDecodeResult r;
	r.handled = true;
	const cv::Mat rows(static_cast<int>(height), static_cast<int>(width), type == CV_16UC1 ? CV_8UC2 : type,
					   raw.data() + 1, stride);
	if (type == CV_8UC3)
		cv::cvtColor(rows, r.image, cv::COLOR_RGB2BGR);
	else if (type == CV_8UC1)
		rows.copyTo(r.image);
	else
	{
		// PNG stores 16-bit samples big-endian.
		r.image.create(static_cast<int>(height), static_cast<int>(width), CV_16UC1);
		for (int y = 0; y < r.image.rows; y++)
		{
			const std::uint8_t* in = rows.ptr<std::uint8_t>(y);
			auto* out = r.image.ptr<std::uint16_t>(y);
			for (int x = 0; x < r.image.cols; x++)
				out[x] = static_cast<std::uint16_t>((in[2 * x] << 8) | in[2 * x + 1]);
		}
	}
	return r;
}

cv::Mat readImageFile(const std::string& path, int imreadFlags, const std::string& what)
{
	std::error_code ec;
	if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "cannot decode " + what + " (not a file)");
	std::ifstream f(path, std::ios::binary | std::ios::ate);
	if (!f) throw InputError(path, "cannot open " + what);
	const std::streamoff size = f.tellg();
	std::vector<std::uint8_t> bytes(size > 0 ? static_cast<std::size_t>(size) : 0);
	f.seekg(0);
	if (size <= 0 || !f.read(reinterpret_cast<char*>(bytes.data()), size))
		throw InputError(path, "cannot decode " + what + " (empty or unreadable file)");
	// A complete PNG ends with its IEND chunk: checked first, for a precise message for the most
	// common damage (a copy cut short), and so that libpng prints nothing of its own to stderr.
	static const std::uint8_t iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82};
	if (bytes.size() >= 8 && bytes[0] == 0x89 && bytes[1] == 'P' && bytes[2] == 'N' && bytes[3] == 'G' &&
		(bytes.size() < 12 || std::memcmp(bytes.data() + bytes.size() - 12, iend, 12) != 0))
		throw InputError(path, "cannot decode " + what + " (truncated PNG: no IEND chunk)");
	const TPngDecodeResult png = decodePng(bytes.data(), bytes.size(), imreadFlags);
	if (png.handled && !png.error.empty()) throw InputError(path, "cannot decode " + what + " (" + png.error + ")");
	if (png.handled) return png.image;
	cv::Mat m;
	try
	{
		m = cv::imdecode(bytes, imreadFlags);
	}
	catch (const cv::Exception&)
	{
		m.release();  // cv::imdecode returns an empty Mat for most damage but throws for some
	}
	if (m.empty()) throw InputError(path, "cannot decode " + what + " (corrupt or not an image)");
	return m;
}
}  // namespace mrpt_yesslam
