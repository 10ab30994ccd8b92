// Writes the rawlog seed corpus (tests/fuzz/corpus/rawlog/): tiny valid rawlogs in both MRPT
// formats, gz and plain, so that the fuzzer starts from real serialized observations.
// Usage: make_rawlog_seeds OUTPUT_FOLDER
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdio>
#include <string>

#include "mrpt_yesslam/io/CRawlogWriter.h"
#include "mrpt_yesslam/io/RgbdObservation.h"

int main(int argc, char** argv)
{
	using namespace mrpt_yesslam;
	if (argc != 2)
	{
		std::fprintf(stderr, "usage: make_rawlog_seeds OUTPUT_FOLDER\n");
		return 1;
	}
	const std::string dir = argv[1];
	TRgbdCamera cam = tumCameraByName("fr3");
	cam.intrinsics.ncols = 4;
	cam.intrinsics.nrows = 3;
	auto frame = [&](int k)
	{
		cv::Mat bgr(3, 4, CV_8UC3, cv::Scalar(10 * k, 20, 30));
		cv::Mat depth(3, 4, CV_16UC1, cv::Scalar(5000 + k));
		return makeRgbdObservation(1000.0 + k / 30.0, bgr, depth, cam);
	};
	for (int level : {0, 1})
	{
		CRawlogWriter w(dir + (level ? "/obs_gz.rawlog" : "/obs_plain.rawlog"), level);
		for (int k = 0; k < 2; k++) w.write(*frame(k));
		w.commit();
	}
	mrpt::io::CFileGZOutputStream f(dir + "/action_sf_plain.rawlog", mrpt::io::OpenMode::TRUNCATE, 0);
	auto arch = mrpt::serialization::archiveFrom(f);
	mrpt::obs::CActionCollection acts;
	mrpt::obs::CSensoryFrame sf;
	sf.insert(frame(0));
	arch << acts << sf;
	return 0;
}
