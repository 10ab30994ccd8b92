#pragma once
// RGB-D camera models: the published TUM Kinect calibrations, and a plain camera file.
#include <mrpt/img/TCamera.h>

#include <optional>
#include <string>

namespace mrpt_yesslam
{
/** Intrinsics of a registered RGB-D camera (depth pixels aligned with colour pixels). */
struct TRgbdCamera
{
	mrpt::img::TCamera intrinsics;  //!< fx fy cx cy, size, distortion k1 k2 p1 p2 k3
	double depthScale = 5000.0;     //!< raw depth value per metre (TUM: 5000, OpenNI: 1000)
	std::string name;               //!< "fr1", "fr2", "fr3" or the camera file it was read from
	/** False for a camera file of four numbers: the size is the images' own (the first image's),
	 * not an assumed 640x480 that an error would then name as if the file had said it. */
	bool sizeGiven = true;
	/** The colour camera's rolling-shutter readout, s from the first row to the last, where known
	 * (the TUM presets and Bonn folders: Kinect v1 and Xtion, 0.028; a camera file's readout
	 * line); -1 = not known, and the run does not correct for it unless [Tracking] rollingShutter says. */
	double readout = -1;
	/** Where `readout` came from, in words (a camera file, a preset, the folder's name); empty when
	 * it is not known. */
	std::string readoutSource;
};

/** The readout of a named sensor, as a camera file's readout line may give it: "kinect1",
 * "kinect", "xtion", "primesense" (PrimeSense designs: 0.028 s, Kerl et al. ICCV 2015) or
 * "global" (0); none for another name. */
std::optional<double> sensorReadout(const std::string& name);

/** The TUM calibration for "fr1"/"freiburg1", "fr2"/"freiburg2", "fr3"/"freiburg3" (TUM's
 * published values; fr1 and fr2 with their distortion, fr3 images are already undistorted).
 * Throws InputError for any other name. */
TRgbdCamera tumCameraByName(const std::string& name);

/** Finds "freiburg1/2/3" or "fr1/2/3" in a path's last folder names; empty if none. */
std::string tumCameraNameFromPath(const std::string& folder);

/** Whether a path belongs to the Bonn RGB-D Dynamic dataset: a folder's name, or a file's name or
 * its folder's, says "bonn" (the dataset's folders are rgbd_bonn_<sequence>, as RTAB-Map recognises them). Decides
 * both the Xtion's readout and the ground truth's marker poses. */
bool isBonnDatasetPath(const std::string& path);

/** Reads a camera file: '#' comments, then "fx fy cx cy [width height [depth_scale]]" on one
 * line, optionally "k1 k2 p1 p2 [k3]" on the next (TUM's d0..d4), and optionally a readout line:
 * the colour camera's rolling-shutter readout in seconds (0 = global shutter) or a sensor's name
 * (sensorReadout), either alone or after the word "readout". Throws InputError. */
TRgbdCamera readCameraFile(const std::string& path);

/** Parses the text of a camera file; `nameForErrors` is used in messages and as the camera name. */
TRgbdCamera parseCameraFile(const std::string& text, const std::string& nameForErrors);

/** The camera file that goes with a recording (a .rawlog or .oni): "<name>_camera.txt" beside it,
 * written by tum2rawlog, yesslam-oni and yesslam --record, so that a replay has the camera's
 * distortion (an .oni holds none) and its rolling-shutter readout (neither format holds one). */
std::string recordingCameraPath(const std::string& recording);
/** A camera file's text for `c` (readCameraFile reads it back): intrinsics with the size, the
 * distortion, and the readout line when the readout is known; `comment` first, as '#' lines. */
std::string formatCameraFile(const TRgbdCamera& c, const std::string& comment);

/** Resolves a --camera argument for a TUM folder: a TUM name, or a camera file; when empty, the
 * folder's calibration.txt if present (in a folder with a freiburg or Bonn name, with the Kinect v1
 * and Xtion readout unless the file gives one), else the freiburg name in the folder path. */
TRgbdCamera resolveTumCamera(const std::string& spec, const std::string& folder);
}  // namespace mrpt_yesslam
