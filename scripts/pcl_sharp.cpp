// PCL's single-scale sharp points, for scripts/compare-sharp.sh: reads a binary PLY of float
// x y z (pcl::io::loadPLYFile), estimates normals and the surface variation
// λ0 / (λ0 + λ1 + λ2) (PCL's `curvature`) with NormalEstimationOMP at k nearest neighbours
// (KdTreeFLANN), labels a point sharp when its curvature is above a threshold, and writes
// x y z label normal curvature as a binary PLY (pcl::io::savePLYFileBinary).
// The threshold is either a fixed value (e.g. 0.02) or `top:N`: the N points of largest
// curvature (the threshold is then the N-th largest value; ties at it are labelled too).
// Prints one line: read, compute (normals + threshold) and write times in seconds, the number
// of points, the number labelled sharp, the threshold used, and how many points are above 0.02.
//   usage: pcl_sharp IN.ply OUT.ply [K=20] [THREADS=2] [THRESHOLD=0.02 | top:N]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <pcl/features/normal_3d_omp.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

static double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s IN.ply OUT.ply [K] [THREADS] [THRESHOLD | top:N]\n", argv[0]);
    return 2;
  }
  const int k = argc > 3 ? std::atoi(argv[3]) : 20;
  const int threads = argc > 4 ? std::atoi(argv[4]) : 2;
  const std::string rule = argc > 5 ? argv[5] : "0.02";

  auto t0 = std::chrono::steady_clock::now();
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  if (pcl::io::loadPLYFile<pcl::PointXYZ>(argv[1], *cloud) < 0) {
    std::fprintf(stderr, "%s: cannot read\n", argv[1]);
    return 1;
  }
  const double read_s = since(t0);

  t0 = std::chrono::steady_clock::now();
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> ne(threads);
  ne.setInputCloud(cloud);
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  ne.setSearchMethod(tree);
  ne.setKSearch(k);
  pcl::PointCloud<pcl::Normal> normals;
  ne.compute(normals);

  float threshold = 0.02f;
  if (rule.rfind("top:", 0) == 0) {
    const std::size_t want = std::strtoull(rule.c_str() + 4, nullptr, 10);
    std::vector<float> c(normals.size());
    for (std::size_t i = 0; i < normals.size(); ++i) {
      const float v = normals[i].curvature;
      c[i] = std::isnan(v) ? 0.0f : v;  // a degenerate neighbourhood is not sharp
    }
    if (want == 0 || c.empty()) {
      threshold = 2.0f;  // above every surface variation (at most 1/3): nothing labelled
    } else {
      const std::size_t nth = std::min(want, c.size()) - 1;
      std::nth_element(c.begin(), c.begin() + nth, c.end(), std::greater<float>());
      threshold = std::nextafter(c[nth], -1.0f);  // label the value itself: curvature > threshold
    }
  } else {
    threshold = std::strtof(rule.c_str(), nullptr);
  }
  pcl::PointCloud<pcl::PointXYZLNormal> out;
  out.resize(cloud->size());
  std::size_t sharp = 0, above_002 = 0;
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    auto& p = out[i];
    p.x = (*cloud)[i].x;
    p.y = (*cloud)[i].y;
    p.z = (*cloud)[i].z;
    p.normal_x = normals[i].normal_x;
    p.normal_y = normals[i].normal_y;
    p.normal_z = normals[i].normal_z;
    p.curvature = normals[i].curvature;
    p.label = p.curvature > threshold ? 1 : 0;
    sharp += p.label;
    above_002 += p.curvature > 0.02f;
  }
  const double compute_s = since(t0);

  t0 = std::chrono::steady_clock::now();
  if (pcl::io::savePLYFileBinary(argv[2], out) < 0) {
    std::fprintf(stderr, "%s: cannot write\n", argv[2]);
    return 1;
  }
  const double write_s = since(t0);
  std::printf("%.3f %.3f %.3f %zu %zu %.6g %zu\n", read_s, compute_s, write_s, out.size(), sharp,
              threshold, above_002);
  return 0;
}
