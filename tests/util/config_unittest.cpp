// Config files: INI and YAML reach the same TOptions; unknown keys warn, wrong types fail.
#include <gtest/gtest.h>

#include <cmath>

#include "TestUtils.h"
#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/dynamic/CDynamicObjectMasker.h"
#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/keyframes/CSemanticKeyFrameSelector.h"
#include "mrpt_yesslam/system/CYesSlamSystem.h"
#include "mrpt_yesslam/geometry/CPoseOptimizer.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/TextParsing.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

TEST(Config, IniAndYamlGiveTheSameOptions)
{
	TempDir d("cfg");
	writeText(d / "a.ini", "; comment\n[Input]\ncamera = fr1\nmaxDiff = 0.03\nsensorLabel = KINECT\n");
	writeText(d / "a.yaml",
			  "# comment\nInput:\n  camera: fr1   # trailing comment\n  maxDiff: 0.03\n  sensorLabel: \"KINECT\"\n");
	for (const char* f : {"a.ini", "a.yaml"})
	{
		SCOPED_TRACE(f);
		CInputSource::TOptions o;
		loadOptionsFromFile(d / f, "Input", o, CInputSource::TOptions::configKeys());
		EXPECT_EQ(o.camera, "fr1");
		EXPECT_DOUBLE_EQ(o.maxDiff, 0.03);
		EXPECT_EQ(o.sensorLabel, "KINECT");
	}
}

TEST(Config, UnknownKeysWarnWrongTypesFail)
{
	auto cfg = parseConfigText("[Input]\nmaxdif = 0.1\nmaxDiff = 0.05\n", false, "c.ini");
	const auto w = validateConfigSection(*cfg, "c.ini", "Input", CInputSource::TOptions::configKeys());
	ASSERT_EQ(w.size(), 1u);
	EXPECT_NE(w[0].find("unknown key 'maxdif'"), std::string::npos);
	EXPECT_NE(w[0].find("known: camera, maxDiff, sensorLabel"), std::string::npos);
	// Key names are case-insensitive, as in MRPT.
	auto cfg2 = parseConfigText("[Input]\nMAXDIFF = x\n", false, "c.ini");
	expectInputError([&] { validateConfigSection(*cfg2, "c.ini", "Input", CInputSource::TOptions::configKeys()); },
					 {"c.ini", "[Input] MAXDIFF = 'x'", "expected a number"});
	// A missing section means defaults.
	EXPECT_TRUE(validateConfigSection(*cfg, "c.ini", "Tracking", {{"x", TConfigKey::Type::Number}}).empty());
	auto cfg3 = parseConfigText("[S]\nn = 2.5\nb = maybe\n", false, "t.ini");
	expectInputError(
		[&] {
			validateConfigSection(*cfg3, "t.ini", "S", {{"n", TConfigKey::Type::Integer}});
		},
		{"expected a whole number"});
	expectInputError(
		[&] {
			validateConfigSection(*cfg3, "t.ini", "S", {{"b", TConfigKey::Type::Boolean}});
		},
		{"expected true or false"});
}

TEST(Config, MalformedYamlNamesTheLine)
{
	expectInputError([] { parseConfigText("Input:\n  - a\n", true, "c.yaml"); }, {"c.yaml", "line 2", "lists"});
	expectInputError([] { parseConfigText("Input:\n  camera fr1\n", true, "c.yaml"); },
					 {"c.yaml", "line 2", "key: value"});
	expectInputError([] { parseConfigText("  camera: fr1\n", true, "c.yaml"); }, {"outside a section"});
	expectInputError([] { parseConfigText("camera: fr1\n", true, "c.yaml"); }, {"must be a section"});
	expectInputError([] { loadConfigFile("/nonexistent/c.yaml"); }, {"/nonexistent/c.yaml", "not found"});
}

TEST(Config, EveryDeclaredKeyIsDumped)
{
	// The key list used for validation and the keys the options print must not drift apart.
	CInputSource::TOptions o;
	std::ostringstream ss;
	o.dumpToTextStream(ss);
	for (const auto& k : CInputSource::TOptions::configKeys())
		EXPECT_NE(ss.str().find(k.name + " "), std::string::npos) << k.name;
}

TEST(Errors, ExceptionSummaryPicksMrptMessage)
{
	EXPECT_EQ(exceptionSummary("==== MRPT exception ====\nMessage:  Cannot read object\nLocation: x.cpp:1\nCall stack "
							   "backtrace:\n[0] 0x1\n"),
			  "Cannot read object");
	EXPECT_EQ(exceptionSummary("plain message\nsecond"), "plain message");
	EXPECT_EQ(exceptionSummary(""), "unknown error");
}

TEST(Config, ShippedDefaultConfigMatchesTheCode)
{
	// share/mrpt_yesslam/config/default.ini lists every key with its default: no unknown keys, no
	// missing ones, and the values it states are the code's defaults.
	const std::string path = std::string(YESSLAM_SOURCE_DIR) + "/share/mrpt_yesslam/config/default.ini";
	const auto cfg = loadConfigFile(path);
	auto check = [&](const std::string& section, const std::vector<TConfigKey>& keys,
					 mrpt::config::CLoadableOptions& loaded, const mrpt::config::CLoadableOptions& defaults)
	{
		SCOPED_TRACE(section);
		EXPECT_TRUE(validateConfigSection(*cfg, path, section, keys).empty());
		std::vector<std::string> present;
		cfg->getAllKeys(section, present);
		EXPECT_EQ(present.size(), keys.size());
		loaded.loadFromConfigFile(*cfg, section);
		std::ostringstream a, b;
		loaded.dumpToTextStream(a);
		defaults.dumpToTextStream(b);
		EXPECT_EQ(a.str(), b.str());
	};
	TDepthNoise cam;
	check("Camera", TDepthNoise::configKeys(), cam, TDepthNoise());
	CInputSource::TOptions in;
	check("Input", CInputSource::TOptions::configKeys(), in, CInputSource::TOptions());
	CObjectDetector::TOptions det;
	check("Detector", CObjectDetector::TOptions::configKeys(), det, CObjectDetector::TOptions());
	CDynamicObjectMasker::TOptions mask;
	check("DynamicMask", CDynamicObjectMasker::TOptions::configKeys(), mask, CDynamicObjectMasker::TOptions());
	CGeometricDynamicCheck::TOptions geo;
	check("GeometricCheck", CGeometricDynamicCheck::TOptions::configKeys(), geo, CGeometricDynamicCheck::TOptions());
	COrbExtractor::TOptions orb;
	check("ORB", COrbExtractor::TOptions::configKeys(), orb, COrbExtractor::TOptions());
	CTracker::TOptions trk;
	check("Tracking", CTracker::TOptions::configKeys(), trk, CTracker::TOptions());
	CKeyFrameInserter::TOptions kf;
	check("KeyFrames", CKeyFrameInserter::TOptions::configKeys(), kf, CKeyFrameInserter::TOptions());
	CLocalMapper::TOptions lm;
	check("LocalMapping", CLocalMapper::TOptions::configKeys(), lm, CLocalMapper::TOptions());
	CLoopCloser::TOptions loop;
	check("LoopClosing", CLoopCloser::TOptions::configKeys(), loop, CLoopCloser::TOptions());
	TYesSlamOptions::TSystem sys;
	check("System", TYesSlamOptions::TSystem::configKeys(), sys, TYesSlamOptions::TSystem());
	COnlinePoseFilter::TOptions online;
	check("OnlinePose", COnlinePoseFilter::TOptions::configKeys(), online, COnlinePoseFilter::TOptions());
	TYesSlamOptions::TOutput output;
	check("Output", TYesSlamOptions::TOutput::configKeys(), output, TYesSlamOptions::TOutput());
}

TEST(Config, ShippedSequenceConfigsHaveOnlyKnownKeys)
{
	// tum_fr1/2/3.ini and sim.ini: every key is one the code reads, with a value of the right type.
	for (const char* name : {"tum_fr1.ini", "tum_fr2.ini", "tum_fr3.ini", "sim.ini"})
	{
		SCOPED_TRACE(name);
		const std::string path = std::string(YESSLAM_SOURCE_DIR) + "/share/mrpt_yesslam/config/" + name;
		const auto cfg = loadConfigFile(path);
		const std::vector<std::pair<std::string, std::vector<TConfigKey>>> sections = {
			{"Input", CInputSource::TOptions::configKeys()},
			{"Detector", CObjectDetector::TOptions::configKeys()},
			{"DynamicMask", CDynamicObjectMasker::TOptions::configKeys()},
			{"ORB", COrbExtractor::TOptions::configKeys()},
			{"GeometricCheck", CGeometricDynamicCheck::TOptions::configKeys()},
			{"Tracking", CTracker::TOptions::configKeys()},
			{"KeyFrames", CKeyFrameInserter::TOptions::configKeys()},
			{"LocalMapping", CLocalMapper::TOptions::configKeys()},
			{"System", TYesSlamOptions::TSystem::configKeys()}};
		std::vector<std::string> all;
		cfg->getAllSections(all);
		for (const auto& s : all)
			EXPECT_TRUE(std::any_of(sections.begin(), sections.end(), [&](const auto& x) { return x.first == s; }))
				<< s;
		for (const auto& [section, keys] : sections)
			EXPECT_TRUE(validateConfigSection(*cfg, path, section, keys).empty()) << section;
		TYesSlamOptions o;
		EXPECT_NO_THROW(o.loadFromFile(path));
	}
}

namespace
{
/** Every options struct of a SLAM run, as its table, bound to `o`. */
std::vector<COptionTable> allTables(TYesSlamOptions& o)
{
	return {o.camera.table(), o.input.table(),    o.detector.table(),  o.masker.table(),  o.geometric.table(),
			o.orb.table(),    o.tracking.table(), o.keyFrames.table(), o.mapping.table(), o.system.table()};
}
}  // namespace

TEST(Config, EveryKeyInAFileReachesItsOption)
{
	// For every key of every section: a file that sets it to another valid value changes exactly
	// that option, and the dump shows it (the table cannot list a key it does not load).
	TYesSlamOptions defaults;
	TempDir d("cfg-keys");
	std::size_t checked = 0;
	for (const COptionTable& t : allTables(defaults))
		for (const auto& e : t.entries())
		{
			SCOPED_TRACE(t.section() + "." + e.key);
			const std::string value = e.other();
			ASSERT_NE(value, e.get());
			writeText(d / "one.ini", "[" + t.section() + "]\n" + e.key + " = " + value + "\n");
			TYesSlamOptions loaded;
			loaded.loadFromFile(d / "one.ini");
			std::size_t changed = 0;
			auto lt = allTables(loaded);
			auto dt = allTables(defaults);
			for (std::size_t i = 0; i < lt.size(); i++)
				for (std::size_t j = 0; j < lt[i].entries().size(); j++)
				{
					const auto& le = lt[i].entries()[j];
					if (le.get() == dt[i].entries()[j].get()) continue;
					changed++;
					EXPECT_EQ(le.key, e.key);
					EXPECT_EQ(le.get(), value);
				}
			EXPECT_EQ(changed, 1u);
			EXPECT_NE(loaded.dump(), defaults.dump());
			checked++;
		}
	EXPECT_GT(checked, 80u);
}

TEST(Config, TheSmoothingKeysAreOutputOptionsAndTheirOldPlaceSaysSo)
{
	// Issue 62: the after-the-run smoothing shapes trajectory_smoothed.txt only ([Output]); a
	// configuration that set it under [Tracking] gets an error naming the file, the key and its
	// new section, not a warning that leaves it at the default.
	TempDir d("cfg-output");
	for (const std::string key : {"smoothingWindow", "correctionWindow", "lostInterpolate"})
	{
		SCOPED_TRACE(key);
		writeText(d / "old.ini", "[Tracking]\n" + key + " = 0\n");
		expectInputError([&] { TYesSlamOptions().loadFromFile(d / "old.ini"); },
						 {"old.ini", "[Tracking] " + key, "[Output] " + key});
	}
	writeText(d / "new.ini", "[Output]\nsmoothingWindow = 4\ncorrectionWindow = 0\nlostInterpolate = false\n");
	TYesSlamOptions o;
	o.loadFromFile(d / "new.ini");
	EXPECT_EQ(o.output.smoothingWindow, 4);
	EXPECT_EQ(o.output.correctionWindow, 0);
	EXPECT_FALSE(o.output.lostInterpolate);
	EXPECT_NE(o.dump().find("[Output]"), std::string::npos);
}

TEST(Config, TheDepthNoiseIsOneCameraOptionAndItsOldKeysSayWhereItWent)
{
	// Issue 42: one depth-noise model for every stage, [Camera] depthNoise. The three keys it
	// replaced would otherwise warn and be ignored, so that a configuration written for them
	// (paper.ini's depthNoise = 0: no depth term) would quietly run with depth: an error names
	// the file, the old key and the new one.
	TempDir d("cfg-noise");
	for (const std::string old : {"[Tracking]\ndepthNoise = 0\n", "[LocalMapping]\ndepthNoise = 0.003\n",
								  "[LoopClosing]\nrefineDepthNoise = 0\n"})
	{
		SCOPED_TRACE(old);
		writeText(d / "old.ini", old);
		try
		{
			TYesSlamOptions o;
			o.loadFromFile(d / "old.ini");
			ADD_FAILURE() << "loaded";
		}
		catch (const InputError& e)
		{
			const std::string m = e.what();
			EXPECT_NE(m.find("old.ini"), std::string::npos) << m;
			EXPECT_NE(m.find("[Camera] depthNoise"), std::string::npos) << m;
			EXPECT_NE(m.find(old.substr(0, old.find('\n'))), std::string::npos) << m;
		}
	}
	writeText(d / "new.ini", "[Camera]\ndepthNoise = 0.004\n");
	TYesSlamOptions o;
	o.loadFromFile(d / "new.ini");
	EXPECT_DOUBLE_EQ(o.camera.depthNoise, 0.004);
	EXPECT_DOUBLE_EQ(o.camera.sigma(2.0), 0.004 * std::pow(2.0, 2.5));  // z^2.5 by default (issue 39 item 2)
	EXPECT_DOUBLE_EQ(o.camera.sigma(2.0, 1.44), 0.004 * std::pow(2.0, 2.5) * 1.44);  // a level-2 keypoint in BA
	writeText(d / "z2.ini", "[Camera]\ndepthNoise = 0.004\ndepthNoiseExponent = 2\n");
	o.loadFromFile(d / "z2.ini");
	EXPECT_DOUBLE_EQ(o.camera.sigma(2.0), 0.016);  // the random disparity noise alone
	EXPECT_FALSE(TDepthNoise::none().used());
	writeText(d / "far.ini", "[Camera]\nfarDepth = 3\n");
	o.loadFromFile(d / "far.ini");
	EXPECT_TRUE(o.camera.measures(2.99));
	EXPECT_FALSE(o.camera.measures(3.01));  // ORB-SLAM2's close/far split
	EXPECT_FALSE(o.camera.measures(0));
	o.camera.farDepth = 0;
	EXPECT_TRUE(o.camera.measures(12.0));  // 0: every depth
	writeText(d / "far_bad.ini", "[Camera]\nfarDepth = -1\n");
	EXPECT_THROW(o.loadFromFile(d / "far_bad.ini"), std::exception);
}

TEST(Config, NegativeCountsAndOutOfRangeValuesAreErrors)
{
	TempDir d("cfg-range");
	const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
		{"[Tracking]\nlocalKeyFrames = -1\n",
		 {"bad.ini", "[Tracking] localKeyFrames = '-1'", "whole number in [1, 10000]"}},
		{"[System]\nframeBuffer = -3\n", {"[System] frameBuffer", "whole number"}},
		{"[LocalMapping]\nfuseKeyFrames = 2.5\n", {"fuseKeyFrames", "whole number"}},
		{"[Input]\nprefetch = 65\n", {"[Input] prefetch = '65'", "in [0, 64]"}},
		{"[Detector]\nconfThreshold = 1.5\n", {"confThreshold", "number in [0, 1]"}},
		{"[KeyFrames]\npolicy = random\n", {"policy = 'random'", "one of semantic, orbslam"}},
		{"[DynamicMask]\nfallbackToBox = maybe\n", {"fallbackToBox", "true or false"}},
		{"[ORB]\nscaleFactor = nan\n", {"scaleFactor", "expected a number"}}};
	for (const auto& [text, words] : cases)
	{
		SCOPED_TRACE(text);
		writeText(d / "bad.ini", text);
		TYesSlamOptions o;
		auto w = words;
		expectInputError([&] { o.loadFromFile(d / "bad.ini"); }, w);
	}
}

TEST(Config, TheDumpOfARunLoadsBackToTheSameOptions)
{
	// config_used.ini reruns a job: the dump is a valid config giving the same options.
	TYesSlamOptions a;
	a.tracking.localKeyFrames = 33;
	a.keyFrames.policy = "orbslam";
	a.masker.method = "box";
	a.input.camera = "fr2";
	TempDir d("cfg-dump");
	writeText(d / "used.ini", a.dump());
	TYesSlamOptions b;
	testing::internal::CaptureStderr();
	b.loadFromFile(d / "used.ini");
	EXPECT_EQ(testing::internal::GetCapturedStderr(), "");  // no unknown key
	EXPECT_EQ(b.dump(), a.dump());
}

TEST(Config, CommentsAfterValuesAreNotPartOfThem)
{
	// Issue 18 item 2: "maxDiff = 0.02  ; pairing window" failed as "expected a number".
	TempDir d("cfg_inline");
	writeText(d / "c.ini",
			  "; a whole-line comment\n"
			  "[Input]\n"
			  "maxDiff = 0.03  ; TUM rgb/depth pairing window, s\n"
			  "[Tracking]\n"
			  "maxDepth = 5\t# far enough\n"
			  "motionRadius = 12 // pixels\n"
			  "[Detector]\n"
			  "dynamicClasses = \"person; chair\"  ; quoted: the ';' inside stays\n");
	TYesSlamOptions o;
	o.loadFromFile(d / "c.ini");
	EXPECT_DOUBLE_EQ(o.input.maxDiff, 0.03);
	EXPECT_DOUBLE_EQ(o.tracking.maxDepth, 5.0);
	EXPECT_DOUBLE_EQ(o.tracking.motionRadius, 12.0);
	EXPECT_EQ(stripInlineIniComments("a = \"x ; y\" ; c\n"), "a = \"x ; y\"\n");
	EXPECT_EQ(stripInlineIniComments("path = /data//x\n"), "path = /data//x\n") << "'//' inside a value is no comment";
}

TEST(Config, IgnoredLinesAndUnknownSectionsWarn)
{
	const auto w = iniStructureWarnings("maxDepth = 3\n[Tracking\nrounds = 2\n[ORB]\nnumFeatures = 900\n", "c.ini");
	ASSERT_EQ(w.size(), 2u);
	EXPECT_NE(w[0].find("c.ini:1"), std::string::npos) << w[0];
	EXPECT_NE(w[0].find("before any [Section]"), std::string::npos) << w[0];
	EXPECT_NE(w[1].find("c.ini:2"), std::string::npos) << w[1];
	EXPECT_NE(w[1].find("closing ']'"), std::string::npos) << w[1];

	TempDir d("cfg_sections");
	writeText(d / "c.ini", "[Trackng]\nmaxDepth = 3\n[ORB]\nnumFeatures = 900\n");
	TYesSlamOptions o;
	testing::internal::CaptureStderr();
	o.loadFromFile(d / "c.ini");
	const std::string err = testing::internal::GetCapturedStderr();
	EXPECT_NE(err.find("unknown section [Trackng]"), std::string::npos) << err;
	EXPECT_NE(err.find("Tracking"), std::string::npos) << err;  // the known ones are listed
	EXPECT_EQ(o.orb.numFeatures, 900);
}

// Issue 43 item 9: a key set twice warns (MRPT takes the last silently), a broken section line
// warns once (not again as a garbled "unknown section"), and warnings carry the tool's name.
TEST(Config, AKeySetTwiceAndABrokenSectionWarnOnceWithTheToolsName)
{
	const auto w = iniStructureWarnings(
		"[ORB]\nnumFeatures = 900\n[Tracking]\nmaxDepth = 5\n[orb]\nNumFeatures = 1000\n", "c.ini");
	ASSERT_EQ(w.size(), 1u);
	EXPECT_NE(w[0].find("c.ini:6: 'NumFeatures' is set again (first on line 2): the last value is used"),
			  std::string::npos)
		<< w[0];
	TempDir d("cfg_twice");
	writeText(d / "c.ini", "[Tracking\nmaxDepth = 5\n[ORB]\nnumFeatures = 900\n");
	TYesSlamOptions o;
	setProgramName("sometool");
	testing::internal::CaptureStderr();
	o.loadFromFile(d / "c.ini");
	const std::string err = testing::internal::GetCapturedStderr();
	setProgramName("mrpt_yesslam");
	EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
	EXPECT_EQ(err.rfind("sometool: warning: ", 0), 0u) << err;
	EXPECT_NE(err.find("closing ']'"), std::string::npos) << err;
}

// Issue 43 item 9: "1 keyframe", never "1 keyframes"; no "-0.000000000" in files.
TEST(TextParsing, CountsReadRightAndZeroHasNoSign)
{
	EXPECT_EQ(countOf(1, "keyframe"), "1 keyframe");
	EXPECT_EQ(countOf(0, "keyframe"), "0 keyframes");
	EXPECT_EQ(countOf(12, "keyframe"), "12 keyframes");
	char b[32];
	std::snprintf(b, sizeof(b), "%.9f", withoutNegativeZero(-1e-12));
	EXPECT_STREQ(b, "0.000000000");
	EXPECT_EQ(withoutNegativeZero(-0.001), -0.001);
}
