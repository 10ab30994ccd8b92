#include "mrpt_yesslam/mapio/GridMapFiles.h"

#include <mrpt/io/CMemoryStream.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/serialization/CArchive.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/TextParsing.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
namespace
{
// map_saver's grey levels.
constexpr std::uint8_t kPgmOccupied = 0, kPgmFree = 254, kPgmUnknown = 205;

std::uint8_t grey(std::int8_t v)
{
	return v == TOccupancyGrid2D::kOccupied ? kPgmOccupied : (v == TOccupancyGrid2D::kFree ? kPgmFree : kPgmUnknown);
}

// The grid as an 8-bit image, one pixel a cell, the first row the largest y (as map_saver).
cv::Mat greyImage(const TOccupancyGrid2D& g)
{
	cv::Mat img(g.height, g.width, CV_8UC1);
	for (int j = 0; j < g.height; j++)
		for (int i = 0; i < g.width; i++) img.at<std::uint8_t>(g.height - 1 - j, i) = grey(g.at(i, j));
	return img;
}
}  // namespace

void writeMrptGridMap(const std::string& path, const TOccupancyGrid2D& g)
{
	const float r = static_cast<float>(g.resolution);
	mrpt::maps::COccupancyGridMap2D m(
		static_cast<float>(g.originX), static_cast<float>(g.originX + g.width * g.resolution),
		static_cast<float>(g.originY), static_cast<float>(g.originY + g.height * g.resolution), r);
	m.fill(0.5f);
	// By each cell's centre: MRPT may round the limits to its own lattice.
	for (int j = 0; j < g.height; j++)
		for (int i = 0; i < g.width; i++)
		{
			const std::int8_t v = g.at(i, j);
			if (v == TOccupancyGrid2D::kUnknown) continue;
			m.setCell(m.x2idx(g.originX + (i + 0.5) * g.resolution), m.y2idx(g.originY + (j + 0.5) * g.resolution),
					  v == TOccupancyGrid2D::kOccupied ? 0.0f : 1.0f);
		}
	mrpt::io::CMemoryStream mem;
	auto arch = mrpt::serialization::archiveFrom(mem);
	arch << m;
	writeFileAtomically(path, mem.getRawBufferData(), static_cast<std::size_t>(mem.getTotalBytesCount()));
}

void writeRosMap(const std::string& yamlPath, const std::string& pgmPath, const TOccupancyGrid2D& g)
{
	std::string pgm = "P5\n# yesslam 2D occupancy grid (map_saver's values: 0 occupied, 254 free, 205 unknown)\n" +
					  std::to_string(g.width) + " " + std::to_string(g.height) + "\n255\n";
	const cv::Mat img = greyImage(g);
	pgm.append(reinterpret_cast<const char*>(img.data), img.total());
	writeFileAtomically(pgmPath, pgm);
	char yaml[640];
	std::snprintf(
		yaml, sizeof yaml,
		"# yesslam 2D occupancy grid: the semantic OctoMap's band %.3f-%.3f m above the floor%s, people never "
		"occupied; z-up world frame of the run\n"
		"image: %s\nresolution: %.6f\norigin: [%.6f, %.6f, 0.0]\nnegate: 0\noccupied_thresh: 0.65\n"
		"free_thresh: 0.196\n",
		g.minZ - g.floorZ, g.maxZ - g.floorZ, g.floorSeen ? "" : " (no floor seen: assumed from the first camera)",
		fs::path(pgmPath).filename().c_str(), g.resolution, g.originX, g.originY);
	writeFileAtomically(yamlPath, yaml);
}

TOccupancyGrid2D readRosMap(const std::string& yamlPath)
{
	std::map<std::string, std::string> kv;
	for (const auto& line : splitLines(readTextFile(yamlPath)))
	{
		const auto colon = line.find(':');
		if (line.empty() || line[0] == '#' || colon == std::string::npos) continue;
		std::string value = line.substr(colon + 1);
		value = value.substr(0, value.find('#'));  // a trailing comment
		value.erase(0, value.find_first_not_of(" \t"));
		value.erase(value.find_last_not_of(" \t\r") + 1);
		kv[line.substr(0, colon)] = value;
	}
	for (const char* key : {"image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh"})
		if (!kv.count(key))
			throw InputError(yamlPath, std::string("no '") + key + "': not a map_server map description");
	TOccupancyGrid2D g;
	double yaw = 0, occ = 0, fre = 0;
	try
	{
		g.resolution = std::stod(kv["resolution"]);
		occ = std::stod(kv["occupied_thresh"]), fre = std::stod(kv["free_thresh"]);
		if (std::sscanf(kv["origin"].c_str(), "[%lf , %lf , %lf]", &g.originX, &g.originY, &yaw) != 3)
			throw std::invalid_argument("origin");
	}
	catch (const std::exception&)
	{
		throw InputError(yamlPath, "resolution, a threshold or origin is not a number (origin: [x, y, yaw])");
	}
	if (!(g.resolution > 0) || yaw != 0 || kv["negate"] != "0")
		throw InputError(yamlPath, "only a positive resolution, yaw 0 and negate 0 are read");
	if (!(fre >= 0 && fre < occ && occ <= 1))
		throw InputError(yamlPath,
						 "free_thresh and occupied_thresh must satisfy 0 <= free_thresh < occupied_thresh <= 1");
	const fs::path image = fs::path(yamlPath).parent_path() / kv["image"];
	const cv::Mat img = cv::imread(image.string(), cv::IMREAD_UNCHANGED);
	if (img.empty() || img.type() != CV_8UC1) throw InputError(image.string(), "not an 8-bit grey map image");
	g.width = img.cols, g.height = img.rows;
	g.cells.resize(static_cast<std::size_t>(g.width) * g.height);
	for (int j = 0; j < g.height; j++)
		for (int i = 0; i < g.width; i++)
		{
			const double p = (255.0 - img.at<std::uint8_t>(g.height - 1 - j, i)) / 255.0;
			g.cells[static_cast<std::size_t>(j) * g.width + i] =
				p > occ ? TOccupancyGrid2D::kOccupied
						: (p < fre ? TOccupancyGrid2D::kFree : TOccupancyGrid2D::kUnknown);
		}
	return g;
}

void writeGridPng(const std::string& path, const TOccupancyGrid2D& g, const std::vector<mrpt::math::TPoint3D>& cams)
{
	if (g.width == 0 || g.height == 0) throw InputError(path, "the grid is empty: no picture to write");
	// A few pixels a cell: about 800 pixels along the longer side, 1 to 8 a cell.
	const int scale = std::clamp(800 / std::max(g.width, g.height), 1, 8);
	cv::Mat img;
	cv::cvtColor(greyImage(g), img, cv::COLOR_GRAY2BGR);
	cv::resize(img, img, cv::Size(), scale, scale, cv::INTER_NEAREST);
	const auto pixel = [&](const mrpt::math::TPoint3D& p)
	{
		return cv::Point(
			static_cast<int>(std::lround((p.x - g.originX) / g.resolution * scale)),
			static_cast<int>(std::lround((g.originY + g.height * g.resolution - p.y) / g.resolution * scale)));
	};
	std::vector<cv::Point> line;
	for (const auto& p : cams) line.push_back(pixel(p));
	if (!line.empty())
	{
		cv::polylines(img, line, false, cv::Scalar(0, 0, 255), std::max(1, scale / 3), cv::LINE_AA);
		cv::circle(img, line.front(), std::max(3, scale), cv::Scalar(0, 160, 0), cv::FILLED, cv::LINE_AA);
	}
	std::vector<std::uint8_t> png;
	if (!cv::imencode(".png", img, png)) throw InputError(path, "the picture could not be encoded as PNG");
	writeFileAtomically(path, png.data(), png.size());
}

void writeGridMapFiles(const std::string& base, const TOccupancyGrid2D& grid,
					   const std::vector<mrpt::math::TPoint3D>& path)
{
	if (grid.width == 0 || grid.height == 0)
		throw InputError(base + ".gridmap",
						 "nothing was seen in the height band and there is no path: no grid to write");
	writeMrptGridMap(base + ".gridmap", grid);
	writeRosMap(base + ".yaml", base + ".pgm", grid);
	writeGridPng(base + ".png", grid, path);
}
}  // namespace mrpt_yesslam
