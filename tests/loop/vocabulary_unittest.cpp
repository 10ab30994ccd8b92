// The ORB vocabulary: training, the binary file (round trip, determinism, corrupt and foreign
// files), place ranking on real frames, the shipped vocabulary and the yesslam-vocab tool.
// Images: TUM RGB-D frames (CC BY 4.0) in ../shared/data, fr2_desk_loop10 via slambook2 (MIT).
#include <gtest/gtest.h>

#include <atomic>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "TestUtils.h"
#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/place/CVocabulary.h"
#include "mrpt_yesslam/place/VocabularyTraining.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/ShareDir.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
cv::Mat descriptorsOf(const std::string& file)
{
	const cv::Mat img = cv::imread(file, cv::IMREAD_GRAYSCALE);
	if (img.empty()) throw std::runtime_error("cannot read " + file);
	return COrbExtractor().extract(img).descriptors;
}

std::vector<std::string> sortedImages(const std::string& dir)
{
	std::vector<std::string> v;
	for (const auto& e : fs::directory_iterator(dir))
		if (e.path().extension() == ".png" && e.path().string().find("depth") == std::string::npos)
			v.push_back(e.path().string());
	std::sort(v.begin(), v.end());
	return v;
}

// Training set: the fr2 desk views and the fr3 walking frames; the fr1 desk frames are held out
// as queries.
const std::vector<cv::Mat>& trainingDescriptors()
{
	static const std::vector<cv::Mat> d = []
	{
		std::vector<cv::Mat> out;
		for (const auto& f : sortedImages(sharedFile("data/tum_sample_frames/fr2_desk_loop10")))
			out.push_back(descriptorsOf(f));
		for (const auto& f : sortedImages(sharedFile("data/tum_sample_frames/fr3_walking")))
			out.push_back(descriptorsOf(f));
		out.push_back(descriptorsOf(sharedFile("data/detector_test_images/person.jpg")));
		return out;
	}();
	return d;
}

CVocabulary smallVocabulary(int threads = 0)
{
	CVocabulary::TTrainOptions o;
	o.branching = 10;
	o.levels = 4;
	o.threads = threads;
	return CVocabulary::train(trainingDescriptors(), o);
}

std::string fileBytes(const std::string& path)
{
	std::ifstream f(path, std::ios::binary);
	return {std::istreambuf_iterator<char>(f), {}};
}

std::string errorOf(const std::function<void()>& f)
{
	try
	{
		f();
	}
	catch (const InputError& e)
	{
		return e.what();
	}
	return "";
}
}  // namespace

TEST(Vocabulary, TrainSaveLoadGivesTheSameWordsAndScores)
{
	const CVocabulary v = smallVocabulary();
	EXPECT_GT(v.numWords(), 2000u);
	EXPECT_LE(v.numWords(), 10000u);
	EXPECT_EQ(v.numTrainingImages(), trainingDescriptors().size());
	TempDir tmp("vocab_roundtrip");
	CVocabulary w = v;
	w.setDescription("round trip");
	w.save(tmp / "v.yvoc");
	const CVocabulary r = CVocabulary::load(tmp / "v.yvoc");
	EXPECT_EQ(r.numWords(), v.numWords());
	EXPECT_EQ(r.numNodes(), v.numNodes());
	EXPECT_EQ(r.description(), "round trip");
	const auto frames = sortedImages(sharedFile("data/tum_fr1_desk_9frames/rgb"));
	const cv::Mat q0 = descriptorsOf(frames[0]), q1 = descriptorsOf(frames[1]);
	for (int i = 0; i < q0.rows; i++) ASSERT_EQ(v.word(q0.ptr<std::uint8_t>(i)), r.word(q0.ptr<std::uint8_t>(i)));
	TBowVector a, b, ra, rb;
	TFeatureVector fa, rfa;
	v.transform(q0, a, &fa, 1);
	v.transform(q1, b);
	r.transform(q0, ra, &rfa, 1);
	r.transform(q1, rb);
	EXPECT_EQ(a, ra);
	EXPECT_EQ(fa, rfa);
	EXPECT_EQ(CVocabulary::score(a, b), CVocabulary::score(ra, rb));
	// A BoW vector is L1-normalised and scores 1 with itself.
	double sum = 0;
	for (const auto& [word, weight] : a) sum += weight;
	EXPECT_NEAR(sum, 1.0, 1e-5);
	EXPECT_NEAR(CVocabulary::score(a, a), 1.0, 1e-6);
	// The direct index holds every descriptor once, under nodes of depth 1.
	std::size_t n = 0;
	for (const auto& [node, idx] : fa)
	{
		n += idx.size();
		EXPECT_LE(node, static_cast<std::uint32_t>(v.branching()));
	}
	EXPECT_EQ(n, static_cast<std::size_t>(q0.rows));
}

TEST(Vocabulary, TheSameDataAndSeedGiveTheSameFileWhateverTheThreads)
{
	TempDir tmp("vocab_determinism");
	smallVocabulary(1).save(tmp / "a.yvoc");
	smallVocabulary(4).save(tmp / "b.yvoc");
	EXPECT_EQ(fileBytes(tmp / "a.yvoc"), fileBytes(tmp / "b.yvoc"));
}

TEST(Vocabulary, CorruptTruncatedAndForeignFilesAreRefusedWithOneLine)
{
	TempDir tmp("vocab_corrupt");
	smallVocabulary().save(tmp / "good.yvoc");
	std::string bytes = fileBytes(tmp / "good.yvoc");
	std::string flipped = bytes;
	flipped[flipped.size() / 2] ^= 0x10;
	std::ofstream(tmp / "flipped.yvoc", std::ios::binary) << flipped;
	std::ofstream(tmp / "truncated.yvoc", std::ios::binary) << bytes.substr(0, bytes.size() - 100);
	const std::string dbow3 = sharedFile("models/dbow3_vocab_slambook2/vocabulary.yml.gz");
	for (const auto& [file, expect] :
		 std::vector<std::pair<std::string, std::string>>{{tmp / "flipped.yvoc", "corrupt"},
														  {tmp / "truncated.yvoc", "corrupt"},
														  {dbow3, "not a yesslam vocabulary"},
														  {tmp / "missing.yvoc", "cannot open"}})
	{
		const std::string e = errorOf([&] { CVocabulary::load(file); });
		EXPECT_NE(e.find(file), std::string::npos) << e;
		EXPECT_NE(e.find(expect), std::string::npos) << e;
		EXPECT_EQ(e.find('\n'), std::string::npos) << e;
	}
}

// Frames of one place score higher against each other than against other places, with a
// vocabulary that never saw them: what loop detection and relocalisation rely on.
void expectPlacesRanked(const CVocabulary& v)
{
	const auto frames = sortedImages(sharedFile("data/tum_fr1_desk_9frames/rgb"));
	ASSERT_EQ(frames.size(), 9u);
	std::vector<TBowVector> desk(frames.size()), other;
	for (std::size_t i = 0; i < frames.size(); i++) v.transform(descriptorsOf(frames[i]), desk[i]);
	for (const auto& f : trainingDescriptors())
	{
		other.emplace_back();
		v.transform(f, other.back());
	}
	for (std::size_t i = 0; i + 1 < desk.size(); i++)
	{
		const double same = CVocabulary::score(desk[i], desk[i + 1]);
		double best = 0;
		for (const auto& o : other) best = std::max(best, CVocabulary::score(desk[i], o));
		EXPECT_GT(same, 2 * best) << "frame " << i;
	}
}

TEST(Vocabulary, NeighbouringFramesOfAnUnseenPlaceScoreAboveOtherPlaces)
{
	expectPlacesRanked(smallVocabulary());
}

TEST(Vocabulary, TheShippedVocabularyLoadsAndRanksPlaces)
{
	const std::string file = shareDir() + "/vocabulary/orb_k10_L5.yvoc";
	const CVocabulary v = CVocabulary::load(file);
	EXPECT_GE(v.numWords(), 10000u);
	EXPECT_GE(v.numTrainingImages(), 1000u);
	EXPECT_LE(fs::file_size(file), 10u << 20);
	expectPlacesRanked(v);
}

TEST(Vocabulary, TheToolTrainsFromAFolderAndReportsTheFile)
{
	TempDir tmp("vocab_tool");
	const auto r = runTool("yesslam-vocab", {"--input", sharedFile("data/tum_sample_frames/fr2_desk_loop10"), "--input",
											 sharedFile("data/tum_fr1_desk_9frames"), "--k", "6", "--levels", "3",
											 "--out", tmp / "v.yvoc", "--quiet"});
	ASSERT_EQ(r.exitCode, 0) << r.err;
	const CVocabulary v = CVocabulary::load(tmp / "v.yvoc");
	// 10 photographs + the 9-frame TUM sequence at every 5th frame (frames 0 and 5).
	EXPECT_EQ(v.numTrainingImages(), 12u);
	EXPECT_NE(v.description().find("12 images"), std::string::npos) << v.description();
	const auto info = runTool("yesslam-vocab", {"--info", tmp / "v.yvoc"});
	EXPECT_EQ(info.exitCode, 0);
	EXPECT_NE(info.out.find("words:     " + std::to_string(v.numWords())), std::string::npos) << info.out;
	// A folder with nothing to train on, and a foreign vocabulary, fail with one line naming them.
	fs::create_directories(tmp / "empty");
	const auto empty = runTool("yesslam-vocab", {"--input", tmp / "empty", "--out", tmp / "x.yvoc"});
	EXPECT_EQ(empty.exitCode, 1);
	EXPECT_NE(empty.err.find(tmp / "empty"), std::string::npos) << empty.err;
	EXPECT_FALSE(fs::exists(tmp / "x.yvoc"));
	const auto foreign =
		runTool("yesslam-vocab", {"--info", sharedFile("models/dbow3_vocab_slambook2/vocabulary.yml.gz")});
	EXPECT_EQ(foreign.exitCode, 1);
	EXPECT_NE(foreign.err.find("not a yesslam vocabulary"), std::string::npos) << foreign.err;
}

TEST(Vocabulary, AFailureInATrainingThreadIsAnErrorNotATermination)
{
	// Issue 28 item 6: the subtrees were built on bare std::threads, so anything thrown there (the
	// progress callback, std::bad_alloc) called std::terminate. Now it reaches the caller.
	CVocabulary::TTrainOptions o;
	o.branching = 10;
	o.levels = 4;
	o.threads = 3;
	std::atomic<int> calls{0};
	try
	{
		CVocabulary::train(trainingDescriptors(), o,
						   [&](std::size_t, std::size_t)
						   {
							   if (++calls == 2) throw std::runtime_error("stopped by the caller");
						   });
		ADD_FAILURE() << "no error";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_STREQ(e.what(), "stopped by the caller");
	}
	EXPECT_LT(calls.load(), 10) << "the other workers stop after their subtree";
	// Training still works after it.
	EXPECT_GT(smallVocabulary(3).numWords(), 0u);
}
