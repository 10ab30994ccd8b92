#include "mrpt_yesslam/io/CInputSource.h"

#include <mrpt/config/CConfigFileBase.h>

#include <filesystem>
#include <fstream>

#include "mrpt_yesslam/io/CRawlogSource.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
void CInputSource::TOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	MRPT_LOAD_CONFIG_VAR(camera, string, c, s);
	MRPT_LOAD_CONFIG_VAR(maxDiff, double, c, s);
	MRPT_LOAD_CONFIG_VAR(sensorLabel, string, c, s);
	MRPT_LOAD_CONFIG_VAR(prefetch, int, c, s);
	if (prefetch < 0 || prefetch > 64) throw InputError("", "[Input] prefetch must be 0..64, got " + std::to_string(prefetch));
}

std::vector<TConfigKey> CInputSource::TOptions::configKeys()
{
	return {{"camera", TConfigKey::Type::Text}, {"maxDiff", TConfigKey::Type::Number}, {"sensorLabel", TConfigKey::Type::Text},
			{"prefetch", TConfigKey::Type::Integer}};
}

void CInputSource::TOptions::dumpToTextStream(std::ostream& out) const
{
	out << "[Input]\n";
	out << "camera      = " << camera << "  ; TUM: fr1|fr2|fr3|camera file; empty = calibration.txt or folder name\n";
	out << "maxDiff     = " << maxDiff << "  ; TUM rgb/depth pairing window, s\n";
	out << "sensorLabel = " << sensorLabel << "  ; rawlog: only this sensor (empty = all)\n";
	out << "prefetch    = " << prefetch << "  ; frames decoded ahead on a reader thread (0 = none)\n";
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
}  // namespace mrpt_yesslam
