//! glTF animations (§3.11): every channel's sampler read through the checked accessors, its keys
//! validated ([`Channel::new`]) and its target resolved to a node of the rendered hierarchy.
//! A morph-target `weights` channel becomes one channel per group of four weights. Channels of
//! nodes outside the rendered scene are checked, then dropped.

use super::{accessor, node_label};
use crate::scene::rig::{Channel, Interpolation, Pose, Property, Rig};
use glam::Vec4;
use gltf::json::animation::{Interpolation as GltfInterpolation, Property as GltfProperty};
use gltf::json::validation::Checked;
use std::collections::hash_map::Entry;
use std::collections::{BTreeMap, HashMap};

fn animation_label(index: usize, name: Option<&str>) -> String {
    match name {
        Some(name) => format!("animation {index} ('{name}')"),
        None => format!("animation {index}"),
    }
}

/// Checks the indices animations hold, which the gltf crate's validator would report only as a
/// JSON path: here the message names the animation and channel.
pub(super) fn check_indices(root: &gltf::json::Root) -> Result<(), String> {
    for (a, anim) in root.animations.iter().enumerate() {
        let name = animation_label(a, anim.name.as_deref());
        for (c, channel) in anim.channels.iter().enumerate() {
            let node = channel.target.node.value();
            if node >= root.nodes.len() {
                return Err(format!(
                    "{name} channel {c} targets node {node}, but the file has {} nodes",
                    root.nodes.len()
                ));
            }
            let sampler = channel.sampler.value();
            if sampler >= anim.samplers.len() {
                return Err(format!(
                    "{name} channel {c} uses sampler {sampler}, but the animation has {}",
                    anim.samplers.len()
                ));
            }
        }
        for (s, sampler) in anim.samplers.iter().enumerate() {
            for (what, accessor) in [("input", sampler.input.value()), ("output", sampler.output.value())] {
                if accessor >= root.accessors.len() {
                    return Err(format!(
                        "{name} sampler {s}: {what} accessor {accessor} does not exist (the file has {})",
                        root.accessors.len()
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The file's translation, rotation and scale channels on `rig`'s nodes (`rig_node_of` maps a
/// glTF node index to its rig node), with warnings about what was ignored; the message names the
/// animation, channel, node and key at fault.
pub(super) fn read(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    rig: &Rig,
    rig_node_of: &[Option<usize>],
) -> Result<(Vec<Channel>, Vec<String>), String> {
    let mut channels = Vec::new();
    let mut warnings = Vec::new();
    // Which channel animates each (rig node, property) first: its animation and its label.
    let mut owner: HashMap<(usize, Property), (usize, String)> = HashMap::new();
    // Channels ignored because an earlier animation animates the same thing, by (animation,
    // earlier animation): one line per pair of clips, not one per channel.
    let mut overlaps: BTreeMap<(usize, usize), Vec<String>> = BTreeMap::new();
    let mut labels = Vec::new();
    // Per animation, its channels on rendered nodes (a clip whose every one of them an earlier
    // clip animates is an alternative take of the same model, not a mistake).
    let mut targeted: Vec<usize> = Vec::new();
    let mut matrix_warned = vec![false; rig.nodes.len()];
    for (a, anim) in doc.as_json().animations.iter().enumerate() {
        let name = animation_label(a, anim.name.as_deref());
        labels.push(name.clone());
        targeted.push(0);
        for (c, json) in anim.channels.iter().enumerate() {
            let node = json.target.node.value();
            let node_name = doc.nodes().nth(node).map_or_else(|| format!("node {node}"), |n| node_label(&n));
            let property = match json.target.path {
                Checked::Valid(GltfProperty::Translation) => Property::Translation,
                Checked::Valid(GltfProperty::Rotation) => Property::Rotation,
                Checked::Valid(GltfProperty::Scale) => Property::Scale,
                Checked::Valid(GltfProperty::MorphTargetWeights) => Property::Weights(0),
                Checked::Invalid => {
                    return Err(format!("{name} channel {c} ({node_name}): unknown target path"));
                }
            };
            let what = format!("{name} channel {c} ({node_name} {property})");
            let fail = |m: String| format!("{what}: {m}");
            let s = json.sampler.value();
            let sampler = anim.samplers.get(s).ok_or_else(|| fail(format!("sampler {s} does not exist")))?;
            let interpolation = match sampler.interpolation {
                Checked::Valid(GltfInterpolation::Step) => Interpolation::Step,
                Checked::Valid(GltfInterpolation::Linear) => Interpolation::Linear,
                Checked::Valid(GltfInterpolation::CubicSpline) => Interpolation::CubicSpline,
                Checked::Invalid => return Err(fail(format!("sampler {s} has an unknown interpolation"))),
            };
            let accessor_at = |i: usize| {
                doc.accessors()
                    .nth(i)
                    .ok_or_else(|| fail(format!("sampler {s}: accessor {i} does not exist")))
            };
            let (input, output) = (accessor_at(sampler.input.value())?, accessor_at(sampler.output.value())?);
            let times = accessor::read_times(&input, buffers).map_err(fail)?;
            let target = rig_node_of.get(node).copied().flatten();
            targeted[a] += usize::from(target.is_some());
            if property == Property::Weights(0) {
                // One channel per group of four weights, each checked and sampled like the rest.
                let count = target.and_then(|t| rig.nodes.get(t)).map_or(0, |n| n.weights.len());
                if count == 0 {
                    if target.is_some() {
                        warnings.push(format!("{what}: the node's mesh has no morph targets; ignored"));
                    }
                    continue;
                }
                let scalars = accessor::read_scalars(&output, buffers, "weights output").map_err(fail)?;
                let per_key = if interpolation == Interpolation::CubicSpline { 3 } else { 1 };
                if scalars.len() != times.len() * per_key * count {
                    return Err(fail(format!(
                        "{} weights for {} keys of {count} targets ({per_key} per key and target)",
                        scalars.len(),
                        times.len()
                    )));
                }
                let Some(target) = target else { continue };
                for g in 0..count.div_ceil(4) {
                    let values = scalars
                        .chunks_exact(count)
                        .map(|row| {
                            Vec4::from_array(std::array::from_fn(|i| {
                                row.get(4 * g + i).copied().unwrap_or(0.0)
                            }))
                        })
                        .collect();
                    let group = u16::try_from(g).map_err(|_| fail(format!("{count} morph targets")))?;
                    let channel =
                        Channel::new(target, Property::Weights(group), interpolation, times.clone(), values)
                            .map_err(fail)?;
                    if let Entry::Vacant(slot) = owner.entry((target, channel.property)) {
                        slot.insert((a, format!("{name} channel {c}")));
                        channels.push(channel);
                    } else if g == 0 {
                        warnings
                            .push(format!("{what}: another channel already animates these weights; ignored"));
                    }
                }
                continue;
            }
            let values = match property {
                Property::Rotation => accessor::read_rotations(&output, buffers),
                _ => accessor::read_vec3(&output, buffers, &format!("{property} output"), accessor::FLOAT)
                    .map(|v| v.into_iter().map(|v| v.extend(0.0)).collect()),
            }
            .map_err(fail)?;
            // Checked even when the node is not rendered: a malformed file is refused either way.
            let channel = Channel::new(target.unwrap_or(usize::MAX), property, interpolation, times, values)
                .map_err(fail)?;
            let Some(target) = target else { continue };
            match owner.entry((target, property)) {
                Entry::Occupied(first) => {
                    let (first_a, first_label) = first.get();
                    let line = format!("{what}: {first_label} already animates this; ignored");
                    overlaps.entry((a, *first_a)).or_default().push(line);
                    continue;
                }
                Entry::Vacant(slot) => {
                    slot.insert((a, format!("{name} channel {c}")));
                }
            }
            if matches!(rig.nodes.get(target).map(|n| n.rest), Some(Pose::Matrix(_)))
                && !matrix_warned[target]
            {
                matrix_warned[target] = true;
                warnings.push(format!(
                    "{node_name} is animated but has a matrix, which glTF forbids; the matrix is split \
                     into translation, rotation and scale"
                ));
            }
            channels.push(channel);
        }
    }
    // Clips wholly over what earlier clips animate (the Khronos Fox's Survey, Walk and Run):
    // the file's first plays, as Blender's importer makes the first its active action, and the
    // others are takes to choose from, not a mistake to warn of.
    let mut overlapped = vec![0usize; labels.len()];
    for ((a, _), lines) in &overlaps {
        overlapped[*a] += lines.len();
    }
    for ((a, first), mut lines) in overlaps {
        if overlapped[a] == targeted[a] {
            continue;
        }
        if lines.len() == 1 {
            warnings.append(&mut lines);
        } else {
            warnings.push(format!(
                "{}: its {} channels animate what {} already animates; ignored (a file's animations \
                 all play at once, from t = 0: export the clip you want on its own)",
                labels[a],
                lines.len(),
                labels[first]
            ));
        }
    }
    Ok((channels, warnings))
}
