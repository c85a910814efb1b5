//! Saving and loading a model's whole state ([`AdaptiveGmm::save`] / [`AdaptiveGmm::load`]);
//! the format is in the parent module's documentation.

use std::io::{Read, Write};

use super::{AdaptiveGmm, GmmError, GmmParams, Pruning, Shape};

impl AdaptiveGmm {
    /// Write the whole model (parameters, frame count, every pixel's mixture) in the format
    /// described in the module documentation.
    pub fn save<W: Write>(&self, out: &mut W) -> Result<(), GmmError> {
        let p = &self.params;
        let mut head = Vec::with_capacity(64);
        head.extend_from_slice(MAGIC);
        // Version 1 has no pruning byte (it is OpenCV's rule); version 2 adds one.
        let version = match p.pruning {
            Pruning::OpenCv => 1u16,
            Pruning::Negative => 2,
        };
        head.extend_from_slice(&version.to_le_bytes());
        head.extend_from_slice(&p.history.to_le_bytes());
        head.extend_from_slice(&p.var_threshold.to_le_bytes());
        head.extend_from_slice(&(p.n_mixtures as u32).to_le_bytes());
        for v in [
            p.background_ratio,
            p.var_threshold_gen,
            p.var_init,
            p.var_min,
            p.var_max,
            p.complexity_reduction,
        ] {
            head.extend_from_slice(&v.to_le_bytes());
        }
        head.push(u8::from(p.detect_shadows));
        head.extend_from_slice(&p.shadow_threshold.to_le_bytes());
        head.push(p.shadow_value);
        if version == 2 {
            head.push(PRUNING_NEGATIVE);
        }
        head.extend_from_slice(&self.frames.to_le_bytes());
        let shape = self.shape.unwrap_or(Shape {
            width: 0,
            height: 0,
            channels: 0,
        });
        head.extend_from_slice(&(shape.width as u32).to_le_bytes());
        head.extend_from_slice(&(shape.height as u32).to_le_bytes());
        head.push(shape.channels as u8);
        out.write_all(&head)?;
        let Some(shape) = self.shape else {
            return Ok(());
        };
        let stride = 2 + shape.channels;
        let mut buf = Vec::with_capacity(shape.width * (1 + 4 * stride * p.n_mixtures));
        for y in 0..shape.height {
            buf.clear();
            for x in 0..shape.width {
                let px = self.pixel_at(shape, x, y);
                let n = self.count(px);
                buf.push(n as u8);
                for k in 0..n {
                    for f in 0..stride {
                        buf.extend_from_slice(&self.field(px, k, f).to_le_bytes());
                    }
                }
            }
            out.write_all(&buf)?;
        }
        Ok(())
    }

    /// Read a model written by [`Self::save`]. Every count and size is checked before use;
    /// a corrupt or truncated input is an error, never a panic or a huge allocation.
    pub fn load<R: Read>(input: &mut R) -> Result<Self, GmmError> {
        let mut r = StateReader(input);
        let mut magic = [0u8; 6];
        r.bytes(&mut magic)?;
        if &magic != MAGIC {
            return Err(bad_state("not a peopletrack GMM state (bad magic)"));
        }
        let version = u16::from_le_bytes(r.array()?);
        if version != 1 && version != 2 {
            return Err(bad_state(format!("format version {version} is not 1 or 2")));
        }
        let history = r.u32()?;
        let var_threshold = r.f32()?;
        let n_mixtures = r.u32()? as usize;
        let [
            background_ratio,
            var_threshold_gen,
            var_init,
            var_min,
            var_max,
            complexity_reduction,
        ] = [r.f32()?, r.f32()?, r.f32()?, r.f32()?, r.f32()?, r.f32()?];
        let detect_shadows = match r.u8()? {
            0 => false,
            1 => true,
            v => return Err(bad_state(format!("detect_shadows byte is {v}"))),
        };
        let shadow_threshold = r.f32()?;
        let shadow_value = r.u8()?;
        let pruning = match (version, if version == 2 { r.u8()? } else { 0 }) {
            (1, _) => Pruning::OpenCv,
            (_, PRUNING_NEGATIVE) => Pruning::Negative,
            (_, b) => return Err(bad_state(format!("pruning byte is {b}"))),
        };
        let params = GmmParams {
            history,
            var_threshold,
            n_mixtures,
            background_ratio,
            var_threshold_gen,
            var_init,
            var_min,
            var_max,
            complexity_reduction,
            detect_shadows,
            shadow_threshold,
            shadow_value,
            pruning,
        };
        let mut model = Self::new(params)?;
        let frames = r.u64()?;
        let (width, height, channels) = (r.u32()? as usize, r.u32()? as usize, r.u8()?);
        if (width, height, channels) == (0, 0, 0) {
            if frames != 0 {
                return Err(bad_state("frames seen but no shape"));
            }
            return Ok(model);
        }
        if width == 0 || height == 0 || width * height > MAX_PIXELS {
            return Err(bad_state(format!("implausible shape {width}x{height}")));
        }
        if channels != 1 && channels != 3 {
            return Err(bad_state(format!("{channels} channels")));
        }
        let shape = Shape {
            width,
            height,
            channels: usize::from(channels),
        };
        model.init(shape);
        model.frames = frames;
        let stride = 2 + shape.channels;
        for y in 0..height {
            for x in 0..width {
                let px = model.pixel_at(shape, x, y);
                let n = r.u8()?;
                if usize::from(n) > n_mixtures {
                    return Err(bad_state(format!(
                        "pixel ({x}, {y}) has {n} components, more than {n_mixtures}"
                    )));
                }
                model.modes[px.group][px.lane] = n;
                for k in 0..usize::from(n) {
                    for f in 0..stride {
                        *model.field_mut(px, k, f) = r.f32()?;
                    }
                }
            }
        }
        let mut extra = [0u8; 1];
        if r.0.read(&mut extra)? != 0 {
            return Err(bad_state("trailing bytes after the last pixel"));
        }
        Ok(model)
    }
}

const MAGIC: &[u8; 6] = b"PTGMM\0";
/// The pruning byte of version 2: [`Pruning::Negative`] (version 1 is [`Pruning::OpenCv`]).
const PRUNING_NEGATIVE: u8 = 1;
/// Largest model [`AdaptiveGmm::load`] accepts (16384 × 16384 pixels).
const MAX_PIXELS: usize = 1 << 28;

fn bad_state(what: impl Into<String>) -> GmmError {
    GmmError::BadState { what: what.into() }
}

/// Little-endian reads that turn a short input into [`GmmError::BadState`].
struct StateReader<'a, R: Read>(&'a mut R);

impl<R: Read> StateReader<'_, R> {
    fn bytes(&mut self, buf: &mut [u8]) -> Result<(), GmmError> {
        self.0.read_exact(buf).map_err(|e| {
            if e.kind() == std::io::ErrorKind::UnexpectedEof {
                bad_state("truncated")
            } else {
                GmmError::Io(e)
            }
        })
    }
    fn array<const N: usize>(&mut self) -> Result<[u8; N], GmmError> {
        let mut b = [0u8; N];
        self.bytes(&mut b)?;
        Ok(b)
    }
    fn u8(&mut self) -> Result<u8, GmmError> {
        Ok(self.array::<1>()?[0])
    }
    fn u32(&mut self) -> Result<u32, GmmError> {
        Ok(u32::from_le_bytes(self.array()?))
    }
    fn u64(&mut self) -> Result<u64, GmmError> {
        Ok(u64::from_le_bytes(self.array()?))
    }
    fn f32(&mut self) -> Result<f32, GmmError> {
        Ok(f32::from_le_bytes(self.array()?))
    }
}
