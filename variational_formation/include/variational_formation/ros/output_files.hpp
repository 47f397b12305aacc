#pragma once

#include <string>

#include <ros/ros.h>

namespace vf {

/**
 * The file-name prefix of the formation in the namespace of `nh`: the namespace that holds it,
 * '/' as '_', then '_' ("team_a_" for /team_a/formation, "" for /formation or the root), so
 * that formations side by side never share an output file.
 */
std::string namespaceFilePrefix(const ros::NodeHandle& nh);

/// `path` with every "{ns}" replaced by namespaceFilePrefix(nh) (the ~result_file and ~bag of
/// formation.launch are "<output_dir>/{ns}<name>...").
std::string outputPath(const ros::NodeHandle& nh, const std::string& path);

/// One ROS_WARN line if `path` holds the result of an earlier run that this run replaces; a
/// file saying "result: running" is this run's own (written before a respawn), not a result.
void announceReplacedResult(const std::string& path);

/**
 * Before a new recording to `path`: one ROS_WARN line naming the earlier bag this replaces, and
 * its later parts (<stem>_1.bag, ...) removed, which would otherwise read as this recording's.
 */
void replaceEarlierBag(const std::string& path);

/**
 * Writes `text` as the whole of the file at `path`: written beside it (`path`.partial) and
 * renamed over it, so a reader sees the old file or the new one, never half of one.
 * @return false on an error writing (nothing replaced).
 */
bool replaceFileWith(const std::string& path, const std::string& text);

/// What appendToResult did.
enum class Appended { notYet, done, failed };

/**
 * Appends `lines` to the run's result file at `path` once the monitor has written its result
 * there (a world's or robot's lines, e.g. contacts), replacing the file whole (replaceFileWith).
 * @return notYet while the file holds no result or "result: running", failed on an error
 * writing (one ROS_ERROR line naming the file).
 */
Appended appendToResult(const std::string& path, const std::string& lines);

/// Creates the directory that will hold `path` (like mkdir -p). @throws InvalidInput naming
/// `parameter` when it cannot.
void createParentDirectory(const std::string& path, const std::string& parameter);

}  // namespace vf
