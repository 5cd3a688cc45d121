// The message conversions of app/ros/ros_messages.h: images of the encodings cameras send
// (mono8, bgr8, rgb8, bayer) to grey with the channel order respected, an unknown encoding
// refused naming it; camera_info to ViSP's one-coefficient radial model, other terms refused.
#include "app/ros/ros_messages.h"

#include <gtest/gtest.h>
#include <sensor_msgs/image_encodings.h>
#include <boost/make_shared.hpp>

#include <cmath>
#include <string>

#include "models/errors.h"

namespace linetrack::app {
namespace {

constexpr int kWidth = 8, kHeight = 6;
// cv_bridge's grey (OpenCV's BT.601 weights, rounded): a pure red pixel is 0.299 * 255.
constexpr int kRedGrey = 76, kBlueGrey = 29;
constexpr int kGreyTol = 1;  // rounding of the weighted sum

sensor_msgs::ImagePtr Image(const std::string& encoding, int channels) {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->encoding = encoding;
  msg->width = kWidth;
  msg->height = kHeight;
  msg->step = kWidth * channels;
  msg->data.assign(static_cast<size_t>(msg->step) * kHeight, 0);
  return msg;
}

// Every pixel (b, g, r) in the order the encoding names.
sensor_msgs::ImagePtr Colour(const std::string& encoding, unsigned char first,
                             unsigned char third) {
  sensor_msgs::ImagePtr msg = Image(encoding, 3);
  for (size_t i = 0; i < msg->data.size(); i += 3) {
    msg->data[i] = first;
    msg->data[i + 2] = third;
  }
  return msg;
}

TEST(RosMessages, GreyImagesOfTheCamerasEncodings) {
  sensor_msgs::ImagePtr mono = Image(sensor_msgs::image_encodings::MONO8, 1);
  for (size_t i = 0; i < mono->data.size(); ++i)
    mono->data[i] = static_cast<unsigned char>(i);
  const vpImage<unsigned char> grey = ToGreyImage(mono);
  ASSERT_EQ(grey.getWidth(), static_cast<unsigned>(kWidth));
  ASSERT_EQ(grey.getHeight(), static_cast<unsigned>(kHeight));
  EXPECT_EQ(grey[2][3], 2 * kWidth + 3);

  // Red in bgr8 is (0, 0, 255); the same bytes in rgb8 are blue.
  EXPECT_NEAR(ToGreyImage(Colour(sensor_msgs::image_encodings::BGR8, 0, 255))[1][1], kRedGrey,
              kGreyTol);
  EXPECT_NEAR(ToGreyImage(Colour(sensor_msgs::image_encodings::RGB8, 0, 255))[1][1], kBlueGrey,
              kGreyTol);

  // A uniform Bayer mosaic is a uniform grey image of the same size.
  sensor_msgs::ImagePtr bayer = Image(sensor_msgs::image_encodings::BAYER_RGGB8, 1);
  std::fill(bayer->data.begin(), bayer->data.end(), 120);
  const vpImage<unsigned char> debayered = ToGreyImage(bayer);
  ASSERT_EQ(debayered.getWidth(), static_cast<unsigned>(kWidth));
  EXPECT_NEAR(debayered[3][4], 120, kGreyTol);

  try {
    ToGreyImage(Image("no_such_encoding", 1));
    ADD_FAILURE() << "an unknown encoding was converted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_encoding"), std::string::npos) << e.what();
  }
}

sensor_msgs::CameraInfo Info(double k1) {
  sensor_msgs::CameraInfo info;
  info.width = 640;
  info.height = 480;
  info.K = {500.0, 0.0, 320.0, 0.0, 510.0, 240.0, 0.0, 0.0, 1.0};
  info.distortion_model = "plumb_bob";
  info.D = {k1, 0.0, 0.0, 0.0, 0.0};
  return info;
}

TEST(RosMessages, CameraInfoGivesVispsRadialModel) {
  const CameraIntrinsics camera = CameraFromInfo(Info(-0.2));
  EXPECT_EQ(camera.width, 640);
  EXPECT_EQ(camera.height, 480);
  EXPECT_DOUBLE_EQ(camera.px, 500.0);
  EXPECT_DOUBLE_EQ(camera.py, 510.0);
  EXPECT_DOUBLE_EQ(camera.u0, 320.0);
  EXPECT_DOUBLE_EQ(camera.v0, 240.0);
  ASSERT_TRUE(camera.has_distortion);
  EXPECT_DOUBLE_EQ(camera.kud, -0.2);  // plumb_bob's x_d = x_u (1 + k1 r_u^2) is ViSP's kud
  // kdu undoes it as the least-squares fit of x_u = x_d (1 + kdu r_d^2) over radii up to the image
  // corner: no worse there than the first-order inverse -k1 (a one-term model cannot be exact).
  const double corner = std::hypot(320.0 / 500.0, 240.0 / 510.0);
  double fitted = 0.0, first_order = 0.0;
  for (int i = 1; i <= 100; ++i) {
    const double ru = corner * i / 100.0;
    const double rd = ru * (1.0 - 0.2 * ru * ru);
    fitted += std::pow(rd * (1.0 + camera.kdu * rd * rd) - ru, 2);
    first_order += std::pow(rd * (1.0 + 0.2 * rd * rd) - ru, 2);
  }
  EXPECT_LT(fitted, first_order);
  EXPECT_GT(camera.kdu, 0.0);  // barrel distortion undone outwards

  EXPECT_FALSE(CameraFromInfo(Info(0.0)).has_distortion);
  sensor_msgs::CameraInfo k2 = Info(-0.2);
  k2.D[1] = 0.05;
  EXPECT_THROW(CameraFromInfo(k2), InputError);  // ViSP's model has no k2: --camera
  sensor_msgs::CameraInfo empty;
  EXPECT_THROW(CameraFromInfo(empty), InputError);
}

}  // namespace
}  // namespace linetrack::app
