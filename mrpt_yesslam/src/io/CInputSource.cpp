#include "mrpt_yesslam/io/CInputSource.h"

#include <mrpt/config/CConfigFileBase.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>

#include "mrpt_yesslam/io/COpenNI2Source.h"
#include "mrpt_yesslam/io/CRawlogSource.h"
#include "mrpt_yesslam/io/RgbdCamera.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/TextParsing.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
COptionTable CInputSource::TOptions::table()
{
	COptionTable t("Input");
	t.text("camera", camera,
		   "TUM folders: fr1, fr2, fr3 or a camera file; empty = calibration.txt in the folder, else the freiburg name "
		   "in its path");
	t.real("maxDiff", maxDiff, 0, 1, "TUM folders: largest rgb/depth stamp difference to pair them, s (associate.py)");
	t.text("sensorLabel", sensorLabel, "rawlogs: only frames with this sensor label (empty = all 3D range scans)");
	t.integer("prefetch", prefetch, 0, 64,
			  "frames decoded ahead on a reader thread (0 = read in the processing thread)");
	return t;
}

std::unique_ptr<CInputSource> openInputSource(const std::string& path, const CInputSource::TOptions& opts)
{
	std::error_code ec;
	if (path.empty()) throw InputError("", "no input given");
	if (!fs::exists(path, ec)) throw InputError(path, "not found");
	if (fs::is_directory(path, ec)) return std::make_unique<CTumFolderSource>(path, opts);
	return std::make_unique<CRawlogSource>(path, opts);
}

std::string findGroundTruthFor(const std::string& inputPath)
{
	std::error_code ec;
	fs::path p(inputPath);
	fs::path cand;
	if (fs::is_directory(p, ec))
		cand = p / "groundtruth.txt";
	else
		cand = p.parent_path() / (p.stem().string() + "_groundtruth.txt");
	return fs::is_regular_file(cand, ec) ? cand.string() : std::string();
}

std::optional<double> statedReadout(const std::string& inputPath)
{
	std::error_code ec;
	const fs::path p(inputPath);
	const fs::path meta = (fs::is_directory(p, ec) ? p : p.parent_path()) / "meta.json";
	if (!fs::is_regular_file(meta, ec)) return std::nullopt;
	std::ifstream f(meta);
	const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
	static const std::regex tool("\"tool\"\\s*:\\s*\"yesslam-sim\""), readout("\"readout_ms\"\\s*:\\s*([0-9.eE+-]+)");
	if (!std::regex_search(text, tool)) return std::nullopt;
	std::smatch m;
	if (!std::regex_search(text, m, readout)) return 0.0;
	double ms = 0;
	if (!parseFiniteDouble(m[1].str(), ms) || ms < 0)
		throw InputError(meta.string(), "readout_ms is not a duration: '" + m[1].str() + "'");
	return ms * 1e-3;
}

TReadout resolveReadout(double configured, const std::string& inputPath, const CInputSource::TOptions& opts)
{
	if (configured >= 0) return {configured, "the configuration ([Tracking] rollingShutter)"};
	if (auto known = knownReadout(inputPath, opts)) return *known;
	return {0.0, "none"};
}

std::optional<TReadout> knownReadout(const std::string& inputPath, const CInputSource::TOptions& opts)
{
	std::error_code ec;
	// --camera for OpenNI2 input is the camera the source uses (over a recording's camera file and
	// the device's own field of view): its readout, when it gives one, is the run's.
	if (isOpenNI2Input(inputPath) && !opts.camera.empty()) try
		{
			const TRgbdCamera c =
				fs::is_regular_file(opts.camera, ec) ? readCameraFile(opts.camera) : tumCameraByName(opts.camera);
			if (c.readout >= 0) return TReadout{c.readout, c.readoutSource};
		}
		catch (const InputError&)
		{
			// Opening the source says what is wrong with it.
		}
	// A recording (a rawlog, an .oni) with its camera file beside it (recordingCameraPath).
	const std::string file =
		isOpenNI2Input(inputPath) ? (inputPath.size() > 8 ? inputPath.substr(8) : std::string()) : inputPath;
	if (!file.empty() && fs::is_regular_file(file, ec))
		if (const std::string side = recordingCameraPath(file); fs::is_regular_file(side, ec))
			if (const TRgbdCamera c = readCameraFile(side); c.readout >= 0)
				return TReadout{c.readout, "the recording's camera file " + side};
	if (isOpenNI2Input(inputPath))
	{
		// A camera: its readout from its name and USB ids (the one the URI names, else the first).
		if (!file.empty() && fs::exists(file, ec)) return std::nullopt;  // a recording without its camera file
		try
		{
			const auto devices = listOpenNI2Devices();
			for (const auto& d : devices)
				if (file.empty() ? &d == &devices.front() : d.uri == file)
					if (const auto r = deviceReadout(d))
						return TReadout{*r, "the device's name (" + d.vendor + " " + d.name + ": a PrimeSense design)"};
		}
		catch (const InputError&)
		{
		}
		return std::nullopt;
	}
	if (const auto stated = statedReadout(inputPath))
		return TReadout{*stated, "the sequence's meta.json (yesslam-sim)"};
	if (!fs::is_directory(inputPath, ec)) return std::nullopt;
	try
	{
		if (const TRgbdCamera c = resolveTumCamera(opts.camera, inputPath); c.readout >= 0)
			return TReadout{c.readout, c.readoutSource};
	}
	catch (const InputError&)
	{
	}
	return std::nullopt;
}
}  // namespace mrpt_yesslam
