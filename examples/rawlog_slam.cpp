// SLAM over the RGB-D observations (CObservation3DRangeScan) of an MRPT rawlog with the
// mrpt_yesslam C++ API: the trajectory in TUM format and the map as a .3Dscene.
//   rawlog_slam IN.rawlog OUT_DIR [CONFIG.ini]
#include <mrpt/img/CImage.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt_yesslam/io/CInputSource.h>
#include <mrpt_yesslam/io/RgbdObservation.h>
#include <mrpt_yesslam/io/SceneExport.h>
#include <mrpt_yesslam/io/WorldFrame.h>
#include <mrpt_yesslam/system/CYesSlamSystem.h>
#include <mrpt_yesslam/system/SlamExport.h>
#include <mrpt_yesslam/util/ShareDir.h>

#include <filesystem>
#include <iostream>

int main(int argc, char** argv)
{
	namespace fs = std::filesystem;
	using namespace mrpt_yesslam;
	if (argc < 3 || argc > 4)
	{
		std::cerr << "usage: rawlog_slam IN.rawlog OUT_DIR [CONFIG.ini]\n";
		return 2;
	}
	try
	{
		// The installed package's model, vocabulary and configurations, wherever the prefix went.
		setShareDir(MRPT_YESSLAM_SHARE_DIR);
		TYesSlamOptions opts;
		if (argc == 4) opts.loadFromFile(argv[3]);
		// The camera's rolling-shutter readout, as yesslam finds it (the rawlog's camera file, when
		// tum2rawlog or yesslam --record wrote one beside it): left unknown, it is not corrected.
		const TReadout readout = resolveReadout(opts.tracking.rollingShutter, argv[1], opts.input);
		opts.tracking.rollingShutter = readout.seconds;
		std::cout << "rawlog_slam: rolling-shutter readout " << readout.seconds << " s, from " << readout.source
				  << "\n";
		CYesSlamSystem slam(opts);
		std::cout << "rawlog_slam: detector " << slam.detector()->description() << "; vocabulary "
				  << (slam.vocabulary() ? "loaded" : "none (no loop closing)") << "\n";

		const fs::path in(argv[1]);
		mrpt::io::CFileGZInputStream file;
		if (!file.open(in.string())) throw std::runtime_error(in.string() + ": cannot open");
		// Images stored beside the rawlog, in MRPT's "<name>_Images" folder.
		mrpt::img::CImage::setImagesPathBase((in.parent_path() / (in.stem().string() + "_Images")).string());
		auto archive = mrpt::serialization::archiveFrom(file);
		mrpt::obs::CActionCollection::Ptr actions;
		mrpt::obs::CSensoryFrame::Ptr sf;
		mrpt::obs::CObservation::Ptr obs;
		std::size_t entry = 0, frames = 0, tracked = 0;
		while (mrpt::obs::CRawlog::getActionObservationPairOrObservation(archive, actions, sf, obs, entry))
		{
			auto scan = std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(obs);
			if (!scan && sf) scan = sf->getObservationByClass<mrpt::obs::CObservation3DRangeScan>();
			if (!scan) continue;
			scan->load();
			validateRgbdObservation(*scan, in.string() + ": entry " + std::to_string(entry));
			if (slam.processFrame(*scan).tracked) tracked++;
			frames++;
		}
		slam.waitForMapping();

		// Exports in the run's world frame (z up, found from the map's floor).
		const TWorldFrame world = slam.worldFrame();
		const TTrajectory trajectory = toWorldFrame(slam.trajectory(), world.worldFromMap);
		fs::create_directories(argv[2]);
		writeTumTrajectory((fs::path(argv[2]) / "trajectory.txt").string(), trajectory,
						   "camera pose (T_w_c)\n" + world.describe());
		saveSceneAtomically(*buildMapScene(slam.map(), trajectory, world.worldFromMap),
							(fs::path(argv[2]) / "map.3Dscene").string());
		std::cout << "rawlog_slam: " << frames << " frames, " << tracked << " tracked, " << slam.map().numKeyFrames()
				  << " keyframes; wrote " << argv[2] << "/trajectory.txt and map.3Dscene\n";
		return 0;
	}
	catch (const std::exception& e)
	{
		std::cerr << "rawlog_slam: error: " << e.what() << "\n";
		return 1;
	}
}
