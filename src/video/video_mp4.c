/* Whether an MP4 file ffmpeg wrote is whole (video_internal.h).
 *
 * An MP4 is a sequence of boxes, each opening with its size and type:
 *
 *   size (4 bytes, big-endian) | type (4 ASCII bytes) | [largesize (8 bytes) if size = 1]
 *
 * size counts the whole box, header included; size 0 means "to the end of
 * the file" (the last box only). ffmpeg writes ftyp first, then the index
 * (moov) and the frames (mdat) in either order (+faststart moves moov
 * before mdat when the file is finished; a fragmented file has an empty
 * moov and moof/mdat pairs). A file cut short by a full disk ends inside
 * a box, or lacks the moov ffmpeg writes last, so the boxes must tile the
 * file exactly and ftyp, moov and mdat must all be there. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "video/video_internal.h"

static uint64_t be(const unsigned char *p, int n)
{
	uint64_t v = 0;
	for (int i = 0; i < n; i++)
		v = v << 8 | p[i];
	return v;
}

int bsim_video_mp4_whole(const char *path, char *why, size_t n)
{
	FILE *f = fopen(path, "rb");
	if (!f) {
		snprintf(why, n, "cannot read it back: %s", strerror(errno));
		return -1;
	}
	uint64_t size = 0, at = 0;
	if (fseek(f, 0, SEEK_END) == 0) {
		long end = ftell(f);
		size = end > 0 ? (uint64_t)end : 0;
	}
	int ftyp = 0, moov = 0, mdat = 0, boxes = 0, rc = 0;
	while (at < size && rc == 0) {
		unsigned char h[16];
		size_t head = 8;
		if (fseek(f, (long)at, SEEK_SET) != 0 || fread(h, 1, 8, f) != 8) {
			snprintf(why, n, "it ends inside a box header at byte %llu",
			         (unsigned long long)at);
			rc = -1;
			break;
		}
		uint64_t len = be(h, 4);
		if (len == 1) {
			head = 16;
			if (fread(h + 8, 1, 8, f) != 8) {
				snprintf(why, n, "it ends inside a box header at byte %llu",
				         (unsigned long long)at);
				rc = -1;
				break;
			}
			len = be(h + 8, 8);
		} else if (len == 0) {
			len = size - at;
		}
		char type[5];
		memcpy(type, h + 4, 4);
		type[4] = '\0';
		for (int i = 0; i < 4; i++)
			if (type[i] < 0x20 || type[i] > 0x7e)
				type[i] = '?';
		if (len < head || len > size - at) {
			snprintf(why, n,
			         "its box '%s' at byte %llu claims %llu bytes, of %llu left", type,
			         (unsigned long long)at, (unsigned long long)len,
			         (unsigned long long)(size - at));
			rc = -1;
			break;
		}
		if (boxes++ == 0 && strcmp(type, "ftyp") != 0) {
			snprintf(why, n, "it does not open with an ftyp box (got '%s')", type);
			rc = -1;
			break;
		}
		ftyp |= strcmp(type, "ftyp") == 0;
		moov |= strcmp(type, "moov") == 0;
		mdat |= strcmp(type, "mdat") == 0;
		at += len;
	}
	fclose(f);
	if (rc == 0 && size == 0) {
		snprintf(why, n, "it is empty");
		rc = -1;
	} else if (rc == 0 && (!ftyp || !moov || !mdat)) {
		snprintf(why, n, "it (%llu bytes) has no %s box", (unsigned long long)size,
		         !moov ? "moov (the index, written last)" : "mdat (the frames)");
		rc = -1;
	}
	return rc;
}
