/* rtsh — saving a file so that it keeps what was there.
 *
 * Every file rtsh writes (images, .rt scenes, .ans frames) goes through
 * file_write_atomic, which does what careful editors do:
 *   - a symbolic link is followed (up to 40 hops): the file it points to is
 *     written, the link stays a link;
 *   - an ordinary file is replaced atomically: the content goes to a
 *     temporary file ".NAME.tmp.PID.XXXXXX" in the same folder, is flushed
 *     and synced, takes the old file's mode, its extended attributes and
 *     its ACL (system.posix_acl_access is one of them), and its owner and
 *     group where permitted, then is renamed over the old file; an
 *     interrupted save leaves the old file whole. A new file gets the mode
 *     and ACL any new file in its folder gets (umask, default ACL);
 *   - a file with several hard links, a file owned by another user (whose
 *     owner could not be kept), a file with an extended attribute that
 *     cannot be copied, a FIFO or a device is written in place, so
 *     the links, the owner and the node stay; a folder whose entries cannot
 *     be changed (read-only folder, writable file) is written in place too.
 *     In place, the whole content is made in memory first, so a failing
 *     render or encoder never truncates the file; file_write_note says what
 *     was done;
 *   - a socket or a folder is refused, and so is a new file in the folder
 *     of device nodes (/dev), where a typo must not create a regular file.
 * Temporary files: a catchable signal that kills rtsh during a save
 * (SIGTERM, SIGHUP, SIGINT, SIGQUIT with no handler of the program's own)
 * removes the temporary file; a handler that ends the process calls
 * atomic_cleanup_on_signal. After a kill -9, the next save of the same file
 * removes the temporary files of its own naming left by processes that no
 * longer run and older than this one.
 */
#ifndef RTSH_ATOMIC_H
#define RTSH_ATOMIC_H

#include <stdbool.h>
#include <stdio.h>

#include "rtsh/error.h"

/* Fills f with the file's content; false with err set on failure. */
typedef bool (*file_writer_fn)(FILE *f, void *ctx, rt_error *err);

/* Writes path as described above; on failure (err says why, with the
 * reason from errno) the old file is untouched. */
bool file_write_atomic(const char *path, file_writer_fn write, void *ctx, rt_error *err);

/* False (err says why, as file_write_atomic would) when path's folder does
 * not exist, so that no file can be written there: a caller about to spend
 * a long render on the file asks first. True otherwise, which is no promise
 * that the write will succeed. */
bool file_folder_exists(const char *path, rt_error *err);

/* A note on how the last successful file_write_atomic of this thread wrote
 * ("x.rt has 2 hard links: written in place to keep them"), or "" when it
 * replaced or created the file as usual. */
const char *file_write_note(void);

/* Async-signal-safe: removes the temporary file of a save in progress, if
 * any. For signal handlers that end the process. */
void atomic_cleanup_on_signal(void);

#endif
