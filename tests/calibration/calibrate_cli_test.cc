// `linetrack calibrate` end to end on OpenCV's sample images: the outputs load back through
// vpXmlParserCamera, cv::FileStorage and yaml-cpp and agree with each other and the report;
// left02 is rejected and reported; bad input exits 2 with one line and writes nothing; a frame
// source (image sequence) works like files.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <visp3/core/vpCameraParameters.h>
#include <visp3/core/vpXmlParserCamera.h>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/support/cli_test.h"

namespace linetrack {
namespace {

namespace fs = std::filesystem;
using test_support::ReadAll;

constexpr double kFileAgreement = 1e-9;  // the same number through two file formats

const std::string kData = std::string(LINETRACK_TEST_DATA) + "/opencv";

class CalibrateCli : public test_support::CliTest {
 protected:
  // Expects exit 2, one line on stderr containing `what`, and no output folder.
  void ExpectBadInput(const std::string& args, const std::string& what) {
    const fs::path out = dir_ / "out";
    const test_support::CommandRun run = Linetrack("calibrate " + args + " --out " + out.string());
    EXPECT_EQ(run.code, 2) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_NE(run.err.find(what), std::string::npos) << run.err;
    EXPECT_FALSE(fs::exists(out));
    for (const auto& entry : fs::directory_iterator(dir_))
      EXPECT_EQ(entry.path().filename().string().find("out.partial"), std::string::npos);
  }
};

TEST_F(CalibrateCli, OutputsLoadBackAndLeft02IsRejected) {
  ASSERT_TRUE(fs::exists(kData + "/left01.jpg"))
      << kData << " is missing: run scripts/fetch_test_data.sh " << LINETRACK_TEST_DATA;
  const fs::path out = dir_ / "left";
  const test_support::CommandRun run = Linetrack(
      "calibrate --images '" + kData + "/left*.jpg' --cols 9 --rows 6 --square 0.025 --out " +
      out.string() + " --name left");
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("rejected left02.jpg"), std::string::npos) << run.out;

  // JSON report: views, fates, errors.
  const nlohmann::json report = nlohmann::json::parse(ReadAll(out / "report.json"));
  EXPECT_EQ(report["views_total"], 13);
  EXPECT_EQ(report["views_used"], 12);
  ASSERT_EQ(report["views_rejected"].size(), 1u);
  EXPECT_EQ(report["views_rejected"][0]["name"], "left02.jpg");
  EXPECT_EQ(report["views_rejected"][0]["status"], "error outlier");
  for (const auto& v : report["views"]) {
    if (v["status"] == "used") {
      EXPECT_LT(v["error_px"]["opencv"].get<double>(), 0.5) << v["name"];
    }
  }

  // ViSP XML: both projection models through ViSP's own parser.
  vpXmlParserCamera parser;
  vpCameraParameters plain, distorted;
  const std::string xml = (out / "camera.xml").string();
  ASSERT_EQ(parser.parse(plain, xml, "left", vpCameraParameters::perspectiveProjWithoutDistortion,
                         640, 480),
            vpXmlParserCamera::SEQUENCE_OK);
  ASSERT_EQ(parser.parse(distorted, xml, "left", vpCameraParameters::perspectiveProjWithDistortion,
                         640, 480),
            vpXmlParserCamera::SEQUENCE_OK);
  const auto& with = report["visp"]["with_distortion"];
  EXPECT_NEAR(distorted.get_px(), with["px"].get<double>(), kFileAgreement * 1e3);
  EXPECT_NEAR(distorted.get_kud(), with["kud"].get<double>(), kFileAgreement);
  EXPECT_NEAR(plain.get_u0(), report["visp"]["without_distortion"]["u0"].get<double>(),
              kFileAgreement * 1e3);

  // OpenCV YAML through cv::FileStorage, ROS camera_info through yaml-cpp: the same model.
  cv::FileStorage fs((out / "opencv.yml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  cv::Mat k, d;
  fs["camera_matrix"] >> k;
  fs["distortion_coefficients"] >> d;
  EXPECT_EQ(static_cast<int>(fs["nframes"]), 12);
  const YAML::Node ros = YAML::LoadFile((out / "camera_info.yaml").string());
  EXPECT_EQ(ros["camera_name"].as<std::string>(), "left");
  EXPECT_EQ(ros["image_width"].as<int>(), 640);
  EXPECT_EQ(ros["distortion_model"].as<std::string>(), "plumb_bob");
  const YAML::Node km = ros["camera_matrix"]["data"], dm = ros["distortion_coefficients"]["data"];
  ASSERT_EQ(km.size(), 9u);
  ASSERT_EQ(dm.size(), 5u);
  EXPECT_NEAR(km[0].as<double>(), k.at<double>(0, 0), kFileAgreement * 1e3);
  EXPECT_NEAR(km[2].as<double>(), k.at<double>(0, 2), kFileAgreement * 1e3);
  EXPECT_NEAR(km[5].as<double>(), k.at<double>(1, 2), kFileAgreement * 1e3);
  EXPECT_NEAR(k.at<double>(0, 0), report["opencv"]["fx"].get<double>(), kFileAgreement * 1e3);
  for (int i = 0; i < 5; ++i) {
    EXPECT_NEAR(dm[static_cast<size_t>(i)].as<double>(), d.at<double>(i), kFileAgreement);
  }

  // Pictures: coverage over the image frame and one overlay per image.
  const cv::Mat coverage = cv::imread((out / "coverage.png").string());
  EXPECT_EQ(coverage.cols, 640);
  EXPECT_EQ(coverage.rows, 480);
  int overlays = 0;
  for (const auto& entry : fs::directory_iterator(out / "overlays")) {
    EXPECT_EQ(cv::imread(entry.path().string()).size(), cv::Size(640, 480));
    ++overlays;
  }
  EXPECT_EQ(overlays, 13);
  EXPECT_FALSE(fs::exists(dir_ / ("left.partial")));
}

TEST_F(CalibrateCli, BadInputExits2AndWritesNothing) {
  ExpectBadInput("--images '" + dir_.string() + "/*.png'", "matches no file");
  ExpectBadInput("--images " + (dir_ / "missing.png").string(), "no such image file");
  std::ofstream(dir_ / "text.png") << "not an image";
  ExpectBadInput("--images " + (dir_ / "text.png").string(), "cannot read the image");
  const std::string grid = "/usr/share/visp-images-data/ViSP-images/calibration/grid36-0";
  ExpectBadInput("--images " + grid + "1.pgm " + grid + "2.pgm", "was found in none");
  ExpectBadInput("--images " + grid + "1.pgm --pattern squares", "--pattern");
  ExpectBadInput("--images " + grid + "1.pgm --cols 6 --rows 6", "orientation");
  ASSERT_TRUE(fs::exists(kData + "/left01.jpg")) << kData << " is missing";
  ExpectBadInput("--images " + kData + "/left01.jpg " + kData + "/left03.jpg",
                 "only 2 usable views");
  cv::imwrite((dir_ / "small.png").string(), cv::Mat(100, 120, CV_8U, cv::Scalar(0)));
  ExpectBadInput("--images " + kData + "/left01.jpg " + (dir_ / "small.png").string(),
                 "differs from left01.jpg");
}

TEST_F(CalibrateCli, FrameSourceSequence) {
  // A printf image sequence read through tracking/'s frame sources: frames with the board
  // become views until --frames are collected.
  ASSERT_TRUE(fs::exists(kData + "/left01.jpg")) << kData << " is missing";
  const char* names[] = {"left01", "left03", "left04", "left05", "left06"};
  for (int i = 0; i < 5; ++i) {
    char file[32];
    std::snprintf(file, sizeof(file), "seq_%02d.jpg", i);
    fs::copy_file(kData + "/" + names[i] + ".jpg", dir_ / file);
  }
  const fs::path out = dir_ / "out";
  const test_support::CommandRun run =
      Linetrack("calibrate --source " + (dir_ / "seq_%02d.jpg").string() + " --frames 4 --out " +
                out.string());
  ASSERT_EQ(run.code, 0) << run.err;
  const nlohmann::json report = nlohmann::json::parse(ReadAll(out / "report.json"));
  EXPECT_EQ(report["views_total"], 4);
  EXPECT_EQ(report["views_used"], 4);
}

}  // namespace
}  // namespace linetrack
