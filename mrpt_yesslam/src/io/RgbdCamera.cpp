#include "mrpt_yesslam/io/RgbdCamera.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <regex>

#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
namespace
{
TRgbdCamera makeCamera(const std::string& name, double fx, double fy, double cx, double cy, const double dist[5],
					   unsigned w = 640, unsigned h = 480, double depthScale = 5000.0)
{
	TRgbdCamera c;
	c.name = name;
	c.depthScale = depthScale;
	c.intrinsics.ncols = w;
	c.intrinsics.nrows = h;
	c.intrinsics.setIntrinsicParamsFromValues(fx, fy, cx, cy);
	for (int i = 0; i < 5; i++) c.intrinsics.dist[i] = dist[i];
	return c;
}

// Kinect v1 and ASUS Xtion (PrimeSense designs) read both images with rolling-shutter CMOS
// sensors; Kerl et al. (ICCV 2015) model them with 28 ms (feature/RollingShutter.h).
constexpr double kPrimeSenseReadout = 0.028;

// The TUM sequences' Kinect v1.
TRgbdCamera withReadout(TRgbdCamera c)
{
	c.readout = kPrimeSenseReadout;
	c.readoutSource = "the " + c.name + " camera preset (Kinect v1)";
	return c;
}

constexpr const char* kSensorNames = "kinect1, kinect, xtion, primesense (0.028 s) or global (0)";

std::string lower(std::string s)
{
	std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
	return s;
}
}  // namespace

TRgbdCamera tumCameraByName(const std::string& nameIn)
{
	// Values from the TUM RGB-D benchmark's "file formats" page (ROS default for depth is not used:
	// TUM depth images are registered to colour, so the colour intrinsics apply to both).
	const std::string n = lower(nameIn);
	if (n == "fr1" || n == "freiburg1")
	{
		const double d[5] = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
		return withReadout(makeCamera("fr1", 517.3, 516.5, 318.6, 255.3, d));
	}
	if (n == "fr2" || n == "freiburg2")
	{
		const double d[5] = {0.2312, -0.7849, -0.0033, -0.0001, 0.9172};
		return withReadout(makeCamera("fr2", 520.9, 521.0, 325.1, 249.7, d));
	}
	if (n == "fr3" || n == "freiburg3")
	{
		const double d[5] = {0, 0, 0, 0, 0};
		return withReadout(makeCamera("fr3", 535.4, 539.2, 320.1, 247.6, d));
	}
	throw InputError("", "unknown camera name '" + nameIn + "' (known: fr1, fr2, fr3, or give a camera file)");
}

std::optional<double> sensorReadout(const std::string& name)
{
	const std::string n = lower(name);
	// Kinect v1 and Xtion are PrimeSense designs; an Astra (Orbbec's own) has no published
	// readout we know of: a measured number belongs in its camera file.
	if (n == "kinect1" || n == "kinect" || n == "xtion" || n == "primesense") return kPrimeSenseReadout;
	if (n == "global") return 0.0;
	return std::nullopt;
}

bool isBonnDatasetPath(const std::string& path)
{
	namespace fs = std::filesystem;
	fs::path p = fs::absolute(fs::path(path)).lexically_normal();
	if (p.filename().empty()) p = p.parent_path();  // "x/rgbd_bonn_y/" and "."
	std::error_code ec;
	// A folder by its own name; a file (groundtruth.txt) by its folder's name and its own.
	const std::string names = fs::is_directory(p, ec)
								  ? p.filename().string()
								  : p.parent_path().filename().string() + "/" + p.filename().string();
	return lower(names).find("bonn") != std::string::npos;
}

std::string tumCameraNameFromPath(const std::string& folder)
{
	namespace fs = std::filesystem;
	std::error_code ec;
	fs::path p = fs::weakly_canonical(fs::path(folder), ec);
	if (ec) p = fs::path(folder);
	static const std::regex re("(freiburg|fr)([123])(?![0-9])", std::regex::icase);
	// Look at the folder itself and its parents (a sequence may sit in "fr3/walking_xyz").
	for (int depth = 0; depth < 3 && !p.empty(); depth++)
	{
		std::string name = p.filename().string();
		if (name.empty()) name = p.string();
		std::smatch m;
		if (std::regex_search(name, m, re)) return "fr" + m[2].str();
		const fs::path parent = p.parent_path();
		if (parent == p) break;
		p = parent;
	}
	return {};
}

TRgbdCamera readCameraFile(const std::string& path)
{
	return parseCameraFile(readTextFile(path), path);
}

TRgbdCamera parseCameraFile(const std::string& text, const std::string& path)
{
	const auto lines = splitLines(text);
	std::vector<std::vector<double>> rows;
	std::optional<double> namedReadout;
	for (std::size_t i = 0; i < lines.size(); i++)
	{
		if (isCommentOrBlank(lines[i])) continue;
		auto fields = splitFields(lines[i]);
		// A readout line in words: "[readout] NAME" or "readout SECONDS" (issue 70).
		const bool worded = !fields.empty() && lower(fields[0]) == "readout";
		if (worded) fields.erase(fields.begin());
		double v;
		if (fields.size() == 1 && !parseFiniteDouble(fields[0], v))
		{
			if (!rows.empty() && !namedReadout)
			{
				namedReadout = sensorReadout(fields[0]);
				if (!namedReadout)
					throw InputError(path, "line " + std::to_string(i + 1) + ": unknown sensor '" + fields[0] +
											   "' for the readout (known: " + kSensorNames + "; or seconds)");
				rows.push_back({*namedReadout});
				continue;
			}
		}
		if (worded && fields.size() != 1)
			throw InputError(path, "line " + std::to_string(i + 1) +
									   ": 'readout' takes one value: seconds or a sensor (" + kSensorNames + ")");
		std::vector<double> row;
		for (const auto& f : fields)
		{
			if (!parseFiniteDouble(f, v))
				throw InputError(path, "line " + std::to_string(i + 1) + ": '" + f + "' is not a finite number");
			row.push_back(v);
		}
		rows.push_back(row);
	}
	if (rows.empty())
		throw InputError(path, "camera file has no numbers (expected 'fx fy cx cy [width height [depth_scale]]')");
	const auto& r = rows[0];
	if (r.size() != 4 && r.size() != 6 && r.size() != 7)
		throw InputError(path, "first line must be 'fx fy cx cy [width height [depth_scale]]', found " +
								   std::to_string(r.size()) + " numbers");
	double dist[5] = {0, 0, 0, 0, 0};
	double readout = -1;
	bool distortionRead = false;
	for (std::size_t k = 1; k < rows.size(); k++)
	{
		if (rows[k].size() == 1 && readout < 0)
		{
			if (!(rows[k][0] >= 0 && rows[k][0] <= 0.1))
				throw InputError(path,
								 "the readout line must give the rolling-shutter readout in seconds, 0 to 0.1 (Kinect "
								 "v1 and Xtion: 0.028; 0 = global shutter)");
			readout = rows[k][0];
		}
		else if ((rows[k].size() == 5 || rows[k].size() == 4) && !distortionRead && k == 1)
		{
			for (std::size_t i = 0; i < rows[k].size(); i++) dist[i] = rows[k][i];
			distortionRead = true;
		}
		else
			throw InputError(path,
							 "after 'fx fy cx cy [width height [depth_scale]]' come at most the distortion 'k1 k2 p1 "
							 "p2 [k3]' and a readout line of one "
							 "number (seconds); line " +
								 std::to_string(k + 1) + " of the numbers has " + std::to_string(rows[k].size()));
	}
	if (r[0] <= 0 || r[1] <= 0) throw InputError(path, "focal lengths must be positive");
	unsigned w = 640, h = 480;
	if (r.size() >= 6)
	{
		if (r[4] < 1 || r[5] < 1 || r[4] > 100000 || r[5] > 100000)
			throw InputError(path, "image size must be positive integers");
		w = static_cast<unsigned>(r[4]);
		h = static_cast<unsigned>(r[5]);
	}
	double ds = 5000.0;
	if (r.size() == 7)
	{
		if (r[6] <= 0) throw InputError(path, "depth_scale must be positive (TUM: 5000, OpenNI: 1000)");
		ds = r[6];
	}
	TRgbdCamera c = makeCamera(path, r[0], r[1], r[2], r[3], dist, w, h, ds);
	c.sizeGiven = r.size() >= 6;
	c.readout = readout;
	if (readout >= 0) c.readoutSource = "the camera file " + path;
	return c;
}

std::string recordingCameraPath(const std::string& recording)
{
	const std::filesystem::path p(recording);
	return (p.parent_path() / (p.stem().string() + "_camera.txt")).string();
}

std::string formatCameraFile(const TRgbdCamera& c, const std::string& comment)
{
	std::string out;
	for (const auto& line : splitLines(comment)) out += "# " + line + "\n";
	const auto& K = c.intrinsics;
	char b[256];
	// The size only where it is known (a camera file without one takes the images').
	if (c.sizeGiven && K.ncols > 0 && K.nrows > 0)
		std::snprintf(b, sizeof b, "%.9g %.9g %.9g %.9g %u %u\n", K.fx(), K.fy(), K.cx(), K.cy(), K.ncols, K.nrows);
	else
		std::snprintf(b, sizeof b, "%.9g %.9g %.9g %.9g\n", K.fx(), K.fy(), K.cx(), K.cy());
	out += b;
	std::snprintf(b, sizeof b, "%.9g %.9g %.9g %.9g %.9g\n", K.dist[0], K.dist[1], K.dist[2], K.dist[3], K.dist[4]);
	out += b;
	if (c.readout >= 0)
	{
		std::snprintf(b, sizeof b, "readout %.9g\n", c.readout);
		out += "# the colour camera's rolling-shutter readout, seconds (" +
			   (c.readoutSource.empty() ? std::string("as recorded") : "from " + c.readoutSource) + ")\n";
		out += b;
	}
	return out;
}

TRgbdCamera resolveTumCamera(const std::string& spec, const std::string& folder)
{
	namespace fs = std::filesystem;
	if (!spec.empty())
	{
		std::error_code ec;
		if (fs::is_regular_file(spec, ec)) return readCameraFile(spec);
		try
		{
			return tumCameraByName(spec);
		}
		catch (const InputError&)
		{
			throw InputError(spec,
							 "--camera is neither a known camera name (fr1, fr2, fr3) nor an existing camera file");
		}
	}
	const fs::path calib = fs::path(folder) / "calibration.txt";
	std::error_code ec;
	if (fs::is_regular_file(calib, ec))
	{
		TRgbdCamera c = readCameraFile(calib.string());
		// The TUM sequences' Kinect v1 (a freiburg name in the path) and the Bonn RGB-D Dynamic
		// dataset's ASUS Xtion (its folders are rgbd_bonn_*).
		if (c.readout < 0 && (isBonnDatasetPath(folder) || !tumCameraNameFromPath(folder).empty()))
		{
			c.readout = kPrimeSenseReadout;
			c.readoutSource =
				std::string("the folder's name (") +
				(isBonnDatasetPath(folder) ? "Bonn RGB-D Dynamic: ASUS Xtion" : "TUM freiburg: Kinect v1") + ")";
		}
		return c;
	}
	const std::string n = tumCameraNameFromPath(folder);
	if (n.empty())
		throw InputError(
			folder,
			"cannot tell the camera: no calibration.txt and no freiburg1/2/3 in the folder name; pass a camera name "
			"(fr1, fr2, fr3) or a camera file");
	TRgbdCamera c = tumCameraByName(n);
	c.readoutSource = "the folder's name (TUM freiburg: Kinect v1)";
	return c;
}
}  // namespace mrpt_yesslam
