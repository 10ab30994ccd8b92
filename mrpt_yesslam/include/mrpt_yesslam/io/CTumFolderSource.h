#pragma once
// Frames straight from a TUM RGB-D folder (rgb.txt, depth.txt, rgb/, depth/): rgb and depth stamps
// are paired as the benchmark's associate.py pairs them; 16-bit depth values are kept exactly.
#include <string>
#include <vector>

#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/io/RgbdCamera.h"

namespace mrpt_yesslam
{
/** One line of a TUM image list (rgb.txt, depth.txt). */
struct TTumListEntry
{
	double t = 0;      //!< seconds
	std::string file;  //!< relative to the folder, as written in the list
};

/** Reads a TUM image list: '#' comments (and the bare "timestamp filename" header some copies
 * have) are skipped; throws InputError for malformed lines or stamps that go backwards. */
std::vector<TTumListEntry> readTumFileList(const std::string& path);

/** Parses the text of a TUM image list; `nameForErrors` is used in messages. */
std::vector<TTumListEntry> parseTumFileList(const std::string& text, const std::string& nameForErrors);

/** One associated RGB-D frame of a TUM folder. */
struct TTumFrame
{
	double tRgb = 0, tDepth = 0;
	std::string rgbPath, depthPath;  //!< full paths
};

/** Streams frames of a TUM RGB-D folder. */
class CTumFolderSource : public CInputSource
{
   public:
	/** Reads the lists and resolves the camera; throws InputError on missing or inconsistent input. */
	explicit CTumFolderSource(const std::string& folder, const TOptions& opts = {});
	mrpt::obs::CObservation3DRangeScan::Ptr next() override;
	std::size_t sizeHint() const override { return frames_.size(); }
	std::size_t skipped() const override { return skipped_; }
	const std::string& path() const override { return folder_; }
	/** depth.txt's stamp of the depth image paired with the colour image stamped `colourTime`. */
	std::optional<double> depthTime(double colourTime) const override;

	/** The associated frames, in time order. */
	const std::vector<TTumFrame>& frames() const { return frames_; }
	/** The camera used for every frame. */
	const TRgbdCamera& camera() const { return camera_; }
	/** Index of the frame the last next() returned. */
	std::size_t lastIndex() const { return next_ - 1; }

   private:
	std::string folder_;
	TRgbdCamera camera_;
	bool sizeFromImage_ = false;  //!< the camera file gave no size: the first image's is used
	std::vector<TTumFrame> frames_;
	std::size_t next_ = 0, skipped_ = 0;
};
}  // namespace mrpt_yesslam
