// yesslam-vocab: trains the ORB bag-of-words vocabulary used for loop detection and
// relocalisation from the user's own images, or prints what a vocabulary file holds.
#include <chrono>
#include <cstdio>

#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/place/VocabularyTraining.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/ProgressBar.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	return runTool(
		"yesslam-vocab",
		[&]() -> int
		{
			TVocabTrainingOptions o;
			std::string out, info, configPath;
			std::size_t k = static_cast<std::size_t>(o.tree.branching),
						levels = static_cast<std::size_t>(o.tree.levels);
			std::size_t seed = o.tree.seed, threads = 0, iterations = static_cast<std::size_t>(o.tree.maxIterations);
			bool quiet = false;
			CommandLine cl(
				"yesslam-vocab",
				"yesslam-vocab --input PATH [--input PATH ...] --out FILE.yvoc [--k 10] [--levels 5] [--step 5]\n"
				"       yesslam-vocab --info FILE.yvoc",
				"Trains a hierarchical k-means vocabulary of ORB descriptors (k-majority centroids, k-means++ "
				"seeding,\n"
				"TF-IDF weights) for loop detection and relocalisation, from photographs, folders of images (searched\n"
				"recursively), TUM RGB-D folders and rawlogs. Descriptors are extracted with the [ORB] settings of\n"
				"--config (the defaults otherwise), which must match the settings SLAM runs with. Up to k^levels "
				"words;\n"
				"train on many more images than a single environment (hundreds to thousands) so the words generalise.\n"
				"The file is a compact checksummed binary that loads in milliseconds. --info prints what a file holds.",
				{"yesslam-vocab --input /usr/share/doc/opencv-doc/examples/data --input rgbd_dataset_freiburg1_desk "
				 "--out my.yvoc",
				 "yesslam-vocab --info share/mrpt_yesslam/vocabulary/orb_k10_L5.yvoc"});
			cl.texts("input", "PATH", "image, image folder, TUM folder or .rawlog to train on", &o.inputs);
			cl.text("out", "FILE", "vocabulary file to write", &out);
			cl.text("info", "FILE", "print the header of a vocabulary file and how long it takes to load, then exit",
					&info);
			cl.count("k", "N", "branching factor (children per node), 2..255", &k);
			cl.count("levels", "L", "depth of the tree, 1..10", &levels);
			cl.count("iterations", "N", "k-majority iterations per node", &iterations);
			cl.count("step", "N", "sequences: use every N-th frame", &o.step);
			cl.count("max-images", "N", "at most N images per input (0 = all)", &o.maxImagesPerInput);
			cl.count("seed", "S", "seed of the k-means++ initialisation (same data + seed = same file)", &seed);
			cl.count("threads", "N", "training threads (0 = all cores); the result does not depend on it", &threads);
			cl.text("config", "FILE", "INI/YAML config whose [ORB] and [Input] sections are used", &configPath);
			cl.flag("quiet", "no progress output", &quiet);
			if (!cl.parse(argc, argv)) return 0;

			if (!info.empty())
			{
				const auto t0 = std::chrono::steady_clock::now();
				const CVocabulary v = CVocabulary::load(info);
				const double ms =
					std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
				std::printf("file:      %s\n", info.c_str());
				std::printf("words:     %zu (k=%d, L=%d, %zu nodes)\n", v.numWords(), v.branching(), v.levels(),
							v.numNodes());
				std::printf("images:    %llu\n", static_cast<unsigned long long>(v.numTrainingImages()));
				std::printf("trained:   %s\n", v.description().c_str());
				// The number saved maps quote (yesslam-map's "vocabulary", a refused --load-map's error).
				std::printf("fingerprint: %016llx\n", static_cast<unsigned long long>(v.fingerprint()));
				std::printf("load ms:   %.1f\n", ms);
				return 0;
			}
			if (o.inputs.empty()) throw InputError("", "missing required option --input (see --help)");
			if (out.empty()) throw InputError("", "missing required option --out (see --help)");
			if (!configPath.empty())
			{
				loadOptionsFromFile(configPath, "ORB", o.orb, COrbExtractor::TOptions::configKeys());
				loadOptionsFromFile(configPath, "Input", o.source, CInputSource::TOptions::configKeys());
			}
			o.tree.branching = static_cast<int>(std::min<std::size_t>(k, 1000));
			o.tree.levels = static_cast<int>(std::min<std::size_t>(levels, 1000));
			o.tree.maxIterations = static_cast<int>(std::min<std::size_t>(iterations, 1000));
			o.tree.seed = seed;
			o.tree.threads = static_cast<int>(std::min<std::size_t>(threads, 1024));

			installInterruptHandler();
			ProgressBar bar("yesslam-vocab", 0, !quiet);
			std::string stage;
			TVocabTrainingSummary sum;
			const CVocabulary v = trainVocabulary(
				o, &sum,
				[&](const std::string& s, std::size_t done, std::size_t total)
				{
					if (s != stage)
					{
						if (!stage.empty()) bar.finish();
						bar = ProgressBar("yesslam-vocab " + s, total, !quiet);
						stage = s;
					}
					bar.setTotal(total);
					bar.update(done);
				},
				[] { return interruptRequested(); });
			bar.finish();
			v.save(out);
			std::printf("images:        %zu%s\n", sum.images,
						sum.interrupted ? " (interrupted: trained on those read)" : "");
			std::printf("descriptors:   %zu\n", sum.descriptors);
			std::printf("words:         %zu (%zu nodes)\n", v.numWords(), v.numNodes());
			std::printf("extract s:     %.1f\n", sum.extractSeconds);
			std::printf("train s:       %.1f\n", sum.trainSeconds);
			std::printf("vocabulary:    %s\n", out.c_str());
			return sum.interrupted ? interruptExitCode() : 0;
		});
}
