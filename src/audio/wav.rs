//! WAV bytes of interleaved 16-bit PCM (what a person listens to), written with the `hound`
//! crate into memory; the caller writes the bytes (atomically, through `report::atomic`).

use std::io::Cursor;

#[derive(Debug, thiserror::Error)]
pub enum WavError {
    #[error("WAV: {samples} samples do not split into {channels} channels")]
    Interleave { samples: usize, channels: u16 },
    // no `#[from]`: a source would be printed twice in an error chain (`From` is below)
    #[error("WAV: {0}")]
    Hound(hound::Error),
}

impl From<hound::Error> for WavError {
    fn from(e: hound::Error) -> Self {
        WavError::Hound(e)
    }
}

/// A WAV file (RIFF, PCM, 16-bit) holding `samples` interleaved over `channels` at
/// `sample_rate` Hz.
pub fn wav_bytes(samples: &[i16], channels: u16, sample_rate: u32) -> Result<Vec<u8>, WavError> {
    if channels == 0 || !samples.len().is_multiple_of(usize::from(channels)) {
        return Err(WavError::Interleave {
            samples: samples.len(),
            channels,
        });
    }
    let spec = hound::WavSpec {
        channels,
        sample_rate,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut buf = Cursor::new(Vec::with_capacity(44 + 2 * samples.len()));
    {
        let mut w = hound::WavWriter::new(&mut buf, spec)?;
        let mut w16 = w.get_i16_writer(samples.len() as u32);
        for &s in samples {
            w16.write_sample(s);
        }
        w16.flush()?;
        w.finalize()?;
    }
    Ok(buf.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_header_and_samples_are_those_of_a_canonical_pcm_wav() {
        let b = wav_bytes(&[1, -2, 300, -32768], 2, 16_000).expect("wav");
        assert_eq!(&b[0..4], b"RIFF");
        assert_eq!(u32::from_le_bytes([b[4], b[5], b[6], b[7]]), 36 + 8);
        assert_eq!(&b[8..16], b"WAVEfmt ");
        assert_eq!(u16::from_le_bytes([b[20], b[21]]), 1, "PCM");
        assert_eq!(u16::from_le_bytes([b[22], b[23]]), 2, "channels");
        assert_eq!(u32::from_le_bytes([b[24], b[25], b[26], b[27]]), 16_000);
        assert_eq!(
            u32::from_le_bytes([b[28], b[29], b[30], b[31]]),
            64_000,
            "byte rate"
        );
        assert_eq!(&b[36..40], b"data");
        let data: Vec<i16> = b[44..]
            .chunks_exact(2)
            .map(|c| i16::from_le_bytes([c[0], c[1]]))
            .collect();
        assert_eq!(data, [1, -2, 300, -32768]);
    }

    #[test]
    fn samples_that_do_not_interleave_are_an_error() {
        assert!(matches!(
            wav_bytes(&[1, 2, 3], 2, 16_000),
            Err(WavError::Interleave { .. })
        ));
    }
}
