// PCL's NormalEstimationOMP at k nearest neighbours (KdTreeFLANN), for scripts/compare-normals.sh.
// Reads a binary PLY of float x y z (pcl::io::loadPLYFile), estimates normals with the given
// number of threads, and prints the best of R runs in seconds.
//   usage: pcl_normals FILE.ply [K=20] [THREADS=2] [RUNS=3]
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include <pcl/features/normal_3d_omp.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE.ply [K] [THREADS] [RUNS]\n", argv[0]);
    return 2;
  }
  const int k = argc > 2 ? std::atoi(argv[2]) : 20;
  const int threads = argc > 3 ? std::atoi(argv[3]) : 2;
  const int runs = argc > 4 ? std::atoi(argv[4]) : 3;
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  if (pcl::io::loadPLYFile<pcl::PointXYZ>(argv[1], *cloud) < 0) {
    std::fprintf(stderr, "%s: cannot read\n", argv[1]);
    return 1;
  }
  double best = 1e300;
  std::size_t count = 0;
  for (int r = 0; r < runs; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> ne(threads);
    ne.setInputCloud(cloud);
    pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
    ne.setSearchMethod(tree);
    ne.setKSearch(k);
    pcl::PointCloud<pcl::Normal> normals;
    ne.compute(normals);
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (s < best) best = s;
    count = normals.size();
  }
  std::printf("%.3f %zu\n", best, count);
  return 0;
}
