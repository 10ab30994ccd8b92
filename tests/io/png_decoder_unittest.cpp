// The libdeflate PNG decoder (io/PngDecoder.h): the same pixels as OpenCV's libpng decoder on real
// dataset frames and on PNGs built here with every row filter, and a clear error for each damage.
#include <gtest/gtest.h>
#include <libdeflate.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "TestUtils.h"
#include "mrpt_yesslam/io/PngDecoder.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
std::vector<std::uint8_t> fileBytes(const std::string& path)
{
	std::ifstream f(path, std::ios::binary);
	return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void put32(std::vector<std::uint8_t>& out, std::uint32_t v)
{
	for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>(v >> s));
}

void chunk(std::vector<std::uint8_t>& out, const char* type, const std::vector<std::uint8_t>& data)
{
	put32(out, static_cast<std::uint32_t>(data.size()));
	const std::size_t start = out.size();
	out.insert(out.end(), type, type + 4);
	out.insert(out.end(), data.begin(), data.end());
	put32(out, libdeflate_crc32(0, out.data() + start, 4 + data.size()));
}

int paethPredictor(int a, int b, int c)
{
	const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
	return (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
}

// A PNG of `img` (CV_8UC3 as BGR, CV_8UC1 or CV_16UC1) written here, independently of libpng: row y
// filtered with filter type y % 5, the zlib stream split over `idatChunks` IDAT chunks, optional
// extra chunks (name, data) before the first IDAT.
std::vector<std::uint8_t> encodePng(const cv::Mat& img, int idatChunks,
									const std::vector<std::pair<std::string, std::vector<std::uint8_t>>>& extra = {})
{
	const int colourType = img.channels() == 3 ? 2 : 0, bitDepth = img.depth() == CV_16U ? 16 : 8;
	const std::size_t bpp = img.elemSize(), rowBytes = img.cols * bpp;
	std::vector<std::uint8_t> raw, prev(rowBytes, 0), cur(rowBytes);
	for (int y = 0; y < img.rows; y++)
	{
		for (int x = 0; x < img.cols; x++)
			for (std::size_t b = 0; b < bpp; b++)
			{
				std::uint8_t v = 0;
				if (img.type() == CV_8UC3) v = img.at<cv::Vec3b>(y, x)[2 - b];  // PNG is RGB
				if (img.type() == CV_8UC1) v = img.at<std::uint8_t>(y, x);
				if (img.type() == CV_16UC1)
					v = static_cast<std::uint8_t>(img.at<std::uint16_t>(y, x) >> (b == 0 ? 8 : 0));
				cur[x * bpp + b] = v;
			}
		const int filter = y % 5;
		raw.push_back(static_cast<std::uint8_t>(filter));
		for (std::size_t i = 0; i < rowBytes; i++)
		{
			const int a = i >= bpp ? cur[i - bpp] : 0, b = prev[i], c = i >= bpp ? prev[i - bpp] : 0;
			const int pred = filter == 0   ? 0
							 : filter == 1 ? a
							 : filter == 2 ? b
							 : filter == 3 ? (a + b) / 2
										   : paethPredictor(a, b, c);
			raw.push_back(static_cast<std::uint8_t>(cur[i] - pred));
		}
		prev = cur;
	}
	libdeflate_compressor* c = libdeflate_alloc_compressor(6);
	std::vector<std::uint8_t> z(libdeflate_zlib_compress_bound(c, raw.size()));
	z.resize(libdeflate_zlib_compress(c, raw.data(), raw.size(), z.data(), z.size()));
	libdeflate_free_compressor(c);

	std::vector<std::uint8_t> out = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A}, ihdr;
	put32(ihdr, static_cast<std::uint32_t>(img.cols));
	put32(ihdr, static_cast<std::uint32_t>(img.rows));
	ihdr.insert(ihdr.end(), {static_cast<std::uint8_t>(bitDepth), static_cast<std::uint8_t>(colourType), 0, 0, 0});
	chunk(out, "IHDR", ihdr);
	for (const auto& [name, data] : extra) chunk(out, name.c_str(), data);
	const std::size_t per = (z.size() + idatChunks - 1) / idatChunks;
	for (std::size_t at = 0; at < z.size(); at += per)
		chunk(out, "IDAT", std::vector<std::uint8_t>(z.begin() + at, z.begin() + std::min(z.size(), at + per)));
	chunk(out, "IEND", {});
	return out;
}

cv::Mat randomImage(int type, unsigned seed)
{
	cv::Mat m(37, 53, type);
	cv::RNG rng(seed);
	rng.fill(m, cv::RNG::UNIFORM, 0, type == CV_16UC1 ? 65536 : 256);
	return m;
}

// The decoded image equals OpenCV's decoding of the same bytes, pixel for pixel.
void expectAsOpenCv(const std::vector<std::uint8_t>& png, int flags, const std::string& what)
{
	const TPngDecodeResult r = decodePng(png.data(), png.size(), flags);
	ASSERT_TRUE(r.handled) << what;
	ASSERT_TRUE(r.error.empty()) << what << ": " << r.error;
	const cv::Mat ref = cv::imdecode(png, flags);
	ASSERT_EQ(r.image.type(), ref.type()) << what;
	ASSERT_EQ(r.image.size(), ref.size()) << what;
	EXPECT_EQ(cv::norm(r.image, ref, cv::NORM_INF), 0.0) << what;
}
}  // namespace

TEST(PngDecoder, RealDatasetFramesGiveOpenCvsPixels)
{
	// Real frames: Bonn RGB-D Dynamic "crowd" (test data only, see its SOURCE.md), TUM fr1/desk and
	// fr2/fr3 samples (TUM RGB-D, CC BY 4.0). Every fifth Bonn frame, colour and depth.
	std::vector<std::pair<std::string, int>> files;
	int n = 0;
	for (const char* sub : {"data/bonn_crowd_dev/rgb", "data/bonn_crowd_dev/depth", "data/tum_fr1_desk_9frames/rgb",
							"data/tum_fr1_desk_9frames/depth"})
	{
		std::vector<fs::path> paths;
		for (const auto& e : fs::directory_iterator(sharedFile(sub))) paths.push_back(e.path());
		std::sort(paths.begin(), paths.end());
		const bool depth = std::string(sub).find("depth") != std::string::npos;
		for (std::size_t i = 0; i < paths.size(); i += std::string(sub).find("bonn") != std::string::npos ? 5 : 1)
			files.emplace_back(paths[i].string(), depth ? cv::IMREAD_UNCHANGED : cv::IMREAD_COLOR);
	}
	for (const auto& e : fs::recursive_directory_iterator(sharedFile("data/tum_sample_frames")))
		if (e.path().extension() == ".png")
			files.emplace_back(e.path().string(), e.path().string().find("depth") != std::string::npos
													  ? cv::IMREAD_UNCHANGED
													  : cv::IMREAD_COLOR);
	ASSERT_GT(files.size(), 100u);
	for (const auto& [path, flags] : files)
	{
		const auto bytes = fileBytes(path);
		const TPngDecodeResult r = decodePng(bytes.data(), bytes.size(), flags);
		ASSERT_TRUE(r.handled) << path << ": a dataset's kind of PNG went to the slow decoder";
		const cv::Mat ref = cv::imread(path, flags);
		ASSERT_EQ(r.image.type(), ref.type()) << path;
		EXPECT_EQ(cv::norm(r.image, ref, cv::NORM_INF), 0.0) << path;
		EXPECT_EQ(cv::norm(readImageFile(path, flags, "image"), ref, cv::NORM_INF), 0.0) << path;
		n++;
	}
	EXPECT_EQ(n, static_cast<int>(files.size()));
}

TEST(PngDecoder, EveryRowFilterAndSplitStreamsDecodeAsLibpngDoes)
{
	unsigned seed = 1;
	for (int type : {CV_8UC3, CV_8UC1, CV_16UC1})
		for (int chunks : {1, 3})
		{
			const cv::Mat img = randomImage(type, seed++);
			const auto png = encodePng(img, chunks);
			expectAsOpenCv(png, cv::IMREAD_UNCHANGED,
						   "type " + std::to_string(type) + ", " + std::to_string(chunks) + " IDAT");
			const TPngDecodeResult r = decodePng(png.data(), png.size(), cv::IMREAD_UNCHANGED);
			EXPECT_EQ(cv::norm(r.image, img, cv::NORM_INF), 0.0) << "not the pixels encoded";
		}
	// Colour as IMREAD_COLOR too (what the TUM reader asks for), with an ancillary chunk before the data.
	const auto png = encodePng(randomImage(CV_8UC3, 9), 2, {{"tEXt", {'a', 0, 'b'}}});
	expectAsOpenCv(png, cv::IMREAD_COLOR, "colour, IMREAD_COLOR");
}

TEST(PngDecoder, OtherKindsAreLeftToOpenCv)
{
	const cv::Mat grey = randomImage(CV_8UC1, 3), depth = randomImage(CV_16UC1, 4);
	// Grey asked as colour, 16-bit asked as colour, a transparency chunk: OpenCV converts these.
	EXPECT_FALSE(decodePng(encodePng(grey, 1).data(), encodePng(grey, 1).size(), cv::IMREAD_COLOR).handled);
	EXPECT_FALSE(decodePng(encodePng(depth, 1).data(), encodePng(depth, 1).size(), cv::IMREAD_COLOR).handled);
	const auto trns = encodePng(randomImage(CV_8UC3, 5), 1, {{"tRNS", {0, 1, 0, 2, 0, 3}}});
	EXPECT_FALSE(decodePng(trns.data(), trns.size(), cv::IMREAD_UNCHANGED).handled);
	// Chunks OpenCV acts on or libpng refuses: an Exif orientation, an unknown critical chunk, image
	// data split by another chunk.
	const cv::Mat rgb = randomImage(CV_8UC3, 6);
	const auto exif = encodePng(rgb, 1, {{"eXIf", {'M', 'M', 0, 42}}});
	EXPECT_FALSE(decodePng(exif.data(), exif.size(), cv::IMREAD_COLOR).handled);
	const auto critical = encodePng(rgb, 1, {{"ABCD", {1, 2}}});
	EXPECT_FALSE(decodePng(critical.data(), critical.size(), cv::IMREAD_COLOR).handled);
	auto split = encodePng(rgb, 2);
	{
		// A tEXt chunk moved between the two IDATs (the first IDAT starts after IHDR, at byte 33).
		const std::size_t first = 33, firstLen = (std::size_t(split[33]) << 24) | (std::size_t(split[34]) << 16) |
												 (std::size_t(split[35]) << 8) | split[36];
		std::vector<std::uint8_t> text;
		chunk(text, "tEXt", {'a', 0, 'b'});
		split.insert(split.begin() + static_cast<std::ptrdiff_t>(first + 12 + firstLen), text.begin(), text.end());
		EXPECT_TRUE(cv::imdecode(split, cv::IMREAD_COLOR).empty()) << "libpng took IDATs split by another chunk";
		EXPECT_FALSE(decodePng(split.data(), split.size(), cv::IMREAD_COLOR).handled);
	}
	// readImageFile still gives what cv::imread gives for them.
	TempDir d("png");
	const std::string path = d.path() + "/grey.png";
	const auto bytes = encodePng(grey, 1);
	std::ofstream(path, std::ios::binary)
		.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
	const cv::Mat viaUs = readImageFile(path, cv::IMREAD_COLOR, "image"), ref = cv::imread(path, cv::IMREAD_COLOR);
	ASSERT_EQ(viaUs.type(), CV_8UC3);
	EXPECT_EQ(cv::norm(viaUs, ref, cv::NORM_INF), 0.0);
}

TEST(PngDecoder, DamageIsReportedNotDecoded)
{
	const auto good = encodePng(randomImage(CV_16UC1, 7), 1);
	// The first IDAT's data start after the signature, IHDR (25 bytes) and the IDAT's length and type.
	const std::size_t idatData = 8 + 25 + 8;
	auto flipped = good;
	flipped[idatData + 10] ^= 0x40;
	TPngDecodeResult r = decodePng(flipped.data(), flipped.size(), cv::IMREAD_UNCHANGED);
	EXPECT_TRUE(r.handled);
	EXPECT_NE(r.error.find("CRC error in IDAT"), std::string::npos) << r.error;

	// The CRC made right again over damaged data: the zlib stream itself is refused.
	const std::uint32_t len = (std::uint32_t(flipped[33]) << 24) | (std::uint32_t(flipped[34]) << 16) |
							  (std::uint32_t(flipped[35]) << 8) | flipped[36];
	const std::uint32_t crc = libdeflate_crc32(0, flipped.data() + 37, 4 + len);
	for (int i = 0; i < 4; i++) flipped[37 + 4 + len + i] = static_cast<std::uint8_t>(crc >> (24 - 8 * i));
	r = decodePng(flipped.data(), flipped.size(), cv::IMREAD_UNCHANGED);
	EXPECT_TRUE(r.handled);
	EXPECT_NE(r.error.find("compressed image data is corrupt"), std::string::npos) << r.error;

	// Cut short, through the file reader: one line naming the file and the problem.
	TempDir d("png");
	const std::string path = d.path() + "/cut.png";
	std::ofstream(path, std::ios::binary)
		.write(reinterpret_cast<const char*>(good.data()), static_cast<std::streamsize>(good.size() / 2));
	try
	{
		readImageFile(path, cv::IMREAD_UNCHANGED, "depth image");
		FAIL() << "a truncated PNG decoded";
	}
	catch (const InputError& e)
	{
		EXPECT_NE(std::string(e.what()).find(path + ": cannot decode depth image (truncated PNG"), std::string::npos)
			<< e.what();
	}
	const std::string text = d.path() + "/text.png";
	std::ofstream(text) << "not an image\n";
	EXPECT_THROW(readImageFile(text, cv::IMREAD_COLOR, "image"), InputError);
	EXPECT_THROW(readImageFile(d.path() + "/missing.png", cv::IMREAD_COLOR, "image"), InputError);
	EXPECT_THROW(readImageFile(d.path(), cv::IMREAD_COLOR, "image"), InputError) << "a folder is not an image";
}
