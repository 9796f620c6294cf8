// SPDX-License-Identifier: MIT
// The ROS 2 types msgraphs publishes, checked against the Humble message definitions: the type
// names rmw_fastrtps registers, and the serialised bytes. The reference bytes come from a
// small CDR writer driven by the .msg field lists below (ros2/common_interfaces and
// ros2/geometry2 at humble; constants and comments left out), independent of the IDL: a field
// out of order or of the wrong type in idl/ros2/RosHumble.idl changes the bytes.
#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "RosHumblePubSubTypes.h"

namespace {

const std::map<std::string, std::string> kHumble = {
    {"builtin_interfaces/Time", "int32 sec\nuint32 nanosec"},
    {"builtin_interfaces/Duration", "int32 sec\nuint32 nanosec"},
    {"std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id"},
    {"std_msgs/ColorRGBA", "float32 r\nfloat32 g\nfloat32 b\nfloat32 a"},
    {"geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z"},
    {"geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z"},
    {"geometry_msgs/Quaternion", "float64 x\nfloat64 y\nfloat64 z\nfloat64 w"},
    {"geometry_msgs/Pose", "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation"},
    {"geometry_msgs/PoseStamped", "std_msgs/Header header\ngeometry_msgs/Pose pose"},
    {"geometry_msgs/Transform",
     "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation"},
    {"geometry_msgs/TransformStamped",
     "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform"},
    {"sensor_msgs/CompressedImage", "std_msgs/Header header\nstring format\nuint8[] data"},
    {"sensor_msgs/PointField", "string name\nuint32 offset\nuint8 datatype\nuint32 count"},
    {"sensor_msgs/PointCloud2",
     "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n"
     "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense"},
    {"visualization_msgs/UVCoordinate", "float32 u\nfloat32 v"},
    {"visualization_msgs/MeshFile", "string filename\nuint8[] data"},
    {"visualization_msgs/Marker",
     "std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n"
     "geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n"
     "builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n"
     "std_msgs/ColorRGBA[] colors\nstring texture_resource\nsensor_msgs/CompressedImage texture\n"
     "visualization_msgs/UVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\n"
     "visualization_msgs/MeshFile mesh_file\nbool mesh_use_embedded_materials"},
    {"visualization_msgs/MarkerArray", "visualization_msgs/Marker[] markers"},
    {"nav_msgs/Path", "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses"},
    {"tf2_msgs/TFMessage", "geometry_msgs/TransformStamped[] transforms"},
};

// Plain little-endian CDR as rmw_fastrtps writes it: 4-byte encapsulation header, then fields
// aligned to their size relative to the end of that header. Every primitive gets the next
// value of a counter; every array has one element.
class ReferenceCdr {
 public:
  std::vector<std::uint8_t> bytes{0x00, 0x01, 0x00, 0x00};  // CDR_LE
  int counter = 1;

  void Message(const std::string& type) {
    std::istringstream fields(kHumble.at(type));
    for (std::string line; std::getline(fields, line);) {
      std::string field_type = line.substr(0, line.find(' '));
      if (field_type.size() > 2 && field_type.compare(field_type.size() - 2, 2, "[]") == 0) {
        Align(4);
        Put<std::uint32_t>(1);
        field_type.resize(field_type.size() - 2);
      }
      Field(field_type);
    }
  }

 private:
  template <typename T>
  void Put(T v) {
    Align(sizeof(T));
    const std::size_t at = bytes.size();
    bytes.resize(at + sizeof(T));
    std::memcpy(&bytes[at], &v, sizeof(T));
  }
  void Align(std::size_t n) {
    while ((bytes.size() - 4) % n != 0) bytes.push_back(0);
  }
  void Field(const std::string& t) {
    const int c = counter++;
    if (t == "int32")
      Put<std::int32_t>(c);
    else if (t == "uint32")
      Put<std::uint32_t>(static_cast<std::uint32_t>(c));
    else if (t == "float32")
      Put<float>(static_cast<float>(c) + 0.5f);
    else if (t == "float64")
      Put<double>(c + 0.25);
    else if (t == "bool")
      Put<std::uint8_t>(static_cast<std::uint8_t>(c % 2));
    else if (t == "uint8")
      Put<std::uint8_t>(static_cast<std::uint8_t>(c));
    else if (t == "string") {
      // Built by append: GCC 12's -Wrestrict misfires on "s" + std::to_string(c) at -O3.
      std::string s = "s";
      s += std::to_string(c);
      Put<std::uint32_t>(static_cast<std::uint32_t>(s.size() + 1));
      bytes.insert(bytes.end(), s.begin(), s.end());
      bytes.push_back(0);
    } else {
      --counter;
      Message(t);
    }
  }
};

// The same values through the generated types, field by field in the IDL's order.
struct Fill {
  int counter = 1;
  std::int32_t I() { return counter++; }
  std::uint32_t U() { return static_cast<std::uint32_t>(counter++); }
  float F() { return static_cast<float>(counter++) + 0.5f; }
  double D() { return counter++ + 0.25; }
  bool B() { return counter++ % 2 != 0; }
  std::uint8_t O() { return static_cast<std::uint8_t>(counter++); }
  std::string S() {
    std::string s = "s";
    s += std::to_string(counter++);
    return s;
  }

  void Header(std_msgs::msg::Header& h) {
    h.stamp().sec(I());
    h.stamp().nanosec(U());
    h.frame_id(S());
  }
  void Pose(geometry_msgs::msg::Pose& p) {
    p.position().x(D()), p.position().y(D()), p.position().z(D());
    p.orientation().x(D()), p.orientation().y(D()), p.orientation().z(D()), p.orientation().w(D());
  }
  void Color(std_msgs::msg::ColorRGBA& c) { c.r(F()), c.g(F()), c.b(F()), c.a(F()); }
};

template <typename PubSub, typename Msg>
std::vector<std::uint8_t> Serialise(Msg& msg) {
  PubSub type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&msg)());
  EXPECT_TRUE(type.serialize(&msg, &payload));
  return {payload.data, payload.data + payload.length};
}

TEST(Ros2Humble, TypeNamesAreTheOnesRmwFastrtpsRegisters) {
  EXPECT_STREQ(visualization_msgs::msg::MarkerArrayPubSubType().getName(),
               "visualization_msgs::msg::dds_::MarkerArray_");
  EXPECT_STREQ(sensor_msgs::msg::PointCloud2PubSubType().getName(),
               "sensor_msgs::msg::dds_::PointCloud2_");
  EXPECT_STREQ(nav_msgs::msg::PathPubSubType().getName(), "nav_msgs::msg::dds_::Path_");
  EXPECT_STREQ(tf2_msgs::msg::TFMessagePubSubType().getName(), "tf2_msgs::msg::dds_::TFMessage_");
}

TEST(Ros2Humble, MarkerArrayBytesFollowTheHumbleDefinition) {
  ReferenceCdr ref;
  ref.Message("visualization_msgs/MarkerArray");
  Fill f;
  visualization_msgs::msg::Marker m;
  f.Header(m.header());
  m.ns(f.S());
  m.id(f.I()), m.type(f.I()), m.action(f.I());
  f.Pose(m.pose());
  m.scale().x(f.D()), m.scale().y(f.D()), m.scale().z(f.D());
  f.Color(m.color());
  m.lifetime().sec(f.I()), m.lifetime().nanosec(f.U());
  m.frame_locked(f.B());
  geometry_msgs::msg::Point p;
  p.x(f.D()), p.y(f.D()), p.z(f.D());
  m.points().push_back(p);
  std_msgs::msg::ColorRGBA c;
  f.Color(c);
  m.colors().push_back(c);
  m.texture_resource(f.S());
  f.Header(m.texture().header());
  m.texture().format(f.S());
  m.texture().data().push_back(f.O());
  visualization_msgs::msg::UVCoordinate uv;
  uv.u(f.F()), uv.v(f.F());
  m.uv_coordinates().push_back(uv);
  m.text(f.S());
  m.mesh_resource(f.S());
  m.mesh_file().filename(f.S());
  m.mesh_file().data().push_back(f.O());
  m.mesh_use_embedded_materials(f.B());
  visualization_msgs::msg::MarkerArray array;
  array.markers().push_back(m);
  EXPECT_EQ(f.counter, ref.counter);
  EXPECT_EQ(Serialise<visualization_msgs::msg::MarkerArrayPubSubType>(array), ref.bytes);
}

TEST(Ros2Humble, PointCloud2PathAndTfBytesFollowTheHumbleDefinitions) {
  {
    ReferenceCdr ref;
    ref.Message("sensor_msgs/PointCloud2");
    Fill f;
    sensor_msgs::msg::PointCloud2 m;
    f.Header(m.header());
    m.height(f.U()), m.width(f.U());
    sensor_msgs::msg::PointField field;
    field.name(f.S()), field.offset(f.U()), field.datatype(f.O()), field.count(f.U());
    m.fields().push_back(field);
    m.is_bigendian(f.B()), m.point_step(f.U()), m.row_step(f.U());
    m.data().push_back(f.O());
    m.is_dense(f.B());
    EXPECT_EQ(Serialise<sensor_msgs::msg::PointCloud2PubSubType>(m), ref.bytes);
  }
  {
    ReferenceCdr ref;
    ref.Message("nav_msgs/Path");
    Fill f;
    nav_msgs::msg::Path m;
    f.Header(m.header());
    geometry_msgs::msg::PoseStamped p;
    f.Header(p.header());
    f.Pose(p.pose_());
    m.poses().push_back(p);
    EXPECT_EQ(Serialise<nav_msgs::msg::PathPubSubType>(m), ref.bytes);
  }
  {
    ReferenceCdr ref;
    ref.Message("tf2_msgs/TFMessage");
    Fill f;
    tf2_msgs::msg::TFMessage m;
    geometry_msgs::msg::TransformStamped t;
    f.Header(t.header());
    t.child_frame_id(f.S());
    auto& x = t.transform_();
    x.translation().x(f.D()), x.translation().y(f.D()), x.translation().z(f.D());
    x.rotation().x(f.D()), x.rotation().y(f.D()), x.rotation().z(f.D()), x.rotation().w(f.D());
    m.transforms().push_back(t);
    EXPECT_EQ(Serialise<tf2_msgs::msg::TFMessagePubSubType>(m), ref.bytes);
  }
}

}  // namespace
