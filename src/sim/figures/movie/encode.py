"""Writing the frames: MP4 (H.264, yuv420p) through imageio-ffmpeg's ffmpeg, frame by frame, or
a GIF through Pillow, which keeps every frame until it writes the file (GIF delays are whole
hundredths of a second)."""

from PIL import Image


def ffmpeg_missing():
    """Why imageio-ffmpeg cannot write an MP4 here (not installed, or no ffmpeg found), or
    None when it can; imageio-ffmpeg is imported only to write MP4s, GIFs do without it."""
    try:
        import imageio_ffmpeg

        imageio_ffmpeg.get_ffmpeg_exe()
    except (ImportError, RuntimeError) as error:
        return " ".join(str(error).split())
    return None


def write_mp4(path, pictures, size, fps, count):
    """Encode ``count`` RGB frames (uint8[h, w, 3]) as H.264 (yuv420p) at ``fps`` into
    ``path``, then count the frames the file holds: OSError unless all are there."""
    import imageio_ffmpeg

    writer = imageio_ffmpeg.write_frames(str(path), size, fps=fps,
                                         pix_fmt_out="yuv420p", ffmpeg_log_level="error",
                                         output_params=["-preset", "veryfast"])
    writer.send(None)
    try:
        for picture in pictures:
            writer.send(picture)
    finally:
        writer.close()
    try:
        written, _ = imageio_ffmpeg.count_frames_and_secs(str(path))
    except RuntimeError as error:
        raise OSError(f"ffmpeg cannot read back {path}: {str(error).splitlines()[0]}") from error
    if written != count:
        raise OSError(f"ffmpeg wrote {written} of {count} frames into {path}")


def write_gif(path, pictures, fps):
    """Write RGB frames (uint8[h, w, 3]) into an animated GIF through Pillow."""
    images = (Image.fromarray(picture) for picture in pictures)
    first = next(images)
    first.save(path, save_all=True, append_images=images, duration=round(1000.0 / fps),
               loop=0)

